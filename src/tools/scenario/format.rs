//! The scenario file's vocabulary: what a RON file may say, field by field.
//!
//! Every type here is plain serde data with `deny_unknown_fields`, so a misspelt field is
//! an error with its line, never silently ignored. Units are SI (m, s, kg, N); angles in
//! degrees where a person types them (`rotation`), radians per second for spins.

use glam::Vec3;
use serde::Deserialize;

use crate::integrator::Integrator;
use crate::particles::Advection;

/// `settings: (..)`: the world. Every field has a default.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields, default)]
pub struct Settings {
    /// The fixed step (s). Default 1/60.
    pub dt: f32,
    /// Substeps per step. Default 4.
    pub substeps: u32,
    /// The integrator. Default `SymplecticEuler`.
    pub integrator: Integrator,
    /// Gravity (m/s²). Default (0, −9.81, 0).
    pub gravity: Vec3,
    /// The effect plugins to build; `None` (the default) builds every one.
    pub plugins: Option<Vec<PluginName>>,
    /// Let resting islands sleep. Default true.
    pub sleep: bool,
    /// How tracers follow the velocity fields. Default `Euler`.
    pub advection: Advection,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            dt: 1.0 / 60.0,
            substeps: 4,
            integrator: Integrator::default(),
            gravity: Vec3::new(0.0, -9.81, 0.0),
            plugins: None,
            sleep: true,
            advection: Advection::default(),
        }
    }
}

/// An effect plugin, by name.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
pub enum PluginName {
    /// [`crate::particles::GravityPlugin`].
    Gravity,
    /// [`crate::particles::DampingPlugin`].
    Damping,
    /// [`crate::particles::VelocityFieldPlugin`].
    VelocityField,
    /// [`crate::springs::SpringPlugin`].
    Springs,
    /// [`crate::rigid::RigidBodyPlugin`].
    RigidBody,
    /// [`crate::collision::CollisionPlugin`].
    Collision,
    /// [`crate::sleep::SleepPlugin`].
    Sleep,
    /// [`crate::joints::JointPlugin`].
    Joints,
    /// [`crate::soft::SoftBodyPlugin`].
    SoftBody,
    /// [`crate::cloth::ClothPlugin`].
    Cloth,
}

/// `(name: "crate", spawn: ..)`: one named thing in the scene.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct EntityEntry {
    /// The name actions and expectations use (unique in the file).
    pub name: String,
    /// What to spawn.
    pub spawn: Spawn,
}

/// What an entity entry spawns. A name stands for every entity the entry spawns (a rope's
/// nodes, a pyramid's boxes); `name[i]` picks one of them (`name[-1]` the last).
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum Spawn {
    /// A static 100 m × 100 m slab whose top is the plane y = 0.
    Ground,
    /// A rigid body with one collider.
    Body {
        /// The collider's shape (m).
        shape: Shape,
        /// Where its centre is (m).
        #[serde(default)]
        at: Vec3,
        /// Euler angles X, Y, Z in degrees, applied in that order.
        #[serde(default)]
        rotation: Vec3,
        /// Initial velocity (m/s).
        #[serde(default)]
        velocity: Vec3,
        /// Initial angular velocity (rad/s).
        #[serde(default)]
        angular_velocity: Vec3,
        /// Dynamic (default), kinematic or static.
        #[serde(default)]
        kind: BodyKind,
        /// Density (kg/m³); default 1000.
        #[serde(default)]
        density: Option<f32>,
        /// Mass (kg), replacing the one from density.
        #[serde(default)]
        mass: Option<f32>,
        /// Friction coefficient; default 0.5.
        #[serde(default)]
        friction: Option<f32>,
        /// Restitution; default 0.
        #[serde(default)]
        restitution: Option<f32>,
        /// Impacts slower than this (m/s) do not bounce; default the world's 1 m/s.
        #[serde(default)]
        restitution_threshold: Option<f32>,
    },
    /// A point mass.
    Particle {
        /// Position (m).
        at: Vec3,
        /// Velocity (m/s).
        #[serde(default)]
        velocity: Vec3,
        /// Mass (kg); default 1.
        #[serde(default = "one")]
        mass: f32,
        /// Pinned: never moves.
        #[serde(default)]
        pinned: bool,
        /// Linear drag c (1/s): f = −c m v.
        #[serde(default)]
        damping: Option<f32>,
    },
    /// A massless tracer carried by the velocity fields.
    Tracer {
        /// Position (m).
        at: Vec3,
    },
    /// A velocity field acting on tracers.
    Field(Field),
    /// A damped spring between two named single entities.
    Spring {
        /// One end (a name or `name[i]`).
        a: String,
        /// The other end.
        b: String,
        /// Stiffness (N/m).
        stiffness: f32,
        /// Damping (N·s/m).
        #[serde(default)]
        damping: f32,
        /// Rest length (m); default the ends' distance at spawn.
        #[serde(default)]
        rest: Option<f32>,
        /// Where it holds `a` (m, in `a`'s body axes from its centre of mass); a rigid
        /// body held off its centre is turned by the spring (a hinge, a door).
        #[serde(default)]
        anchor_a: Vec3,
        /// Where it holds `b` (m, in `b`'s body axes from its centre of mass).
        #[serde(default)]
        anchor_b: Vec3,
    },
    /// A joint between two named bodies, or a body and the world (`a` left out).
    Joint {
        /// What it holds and leaves free.
        kind: JointKind,
        /// One body (a name or `name[i]`); left out, the world.
        #[serde(default)]
        a: Option<String>,
        /// The other body.
        b: String,
        /// Where it holds `a` (m, in `a`'s shape axes; a world point when `a` is left out).
        #[serde(default)]
        anchor_a: Vec3,
        /// Where it holds `b` (m, in `b`'s shape axes).
        #[serde(default)]
        anchor_b: Vec3,
        /// Let the two bodies collide with each other (by default they do not).
        #[serde(default)]
        collide: bool,
        /// Breaks once its force passes this (N).
        #[serde(default)]
        break_force: Option<f32>,
    },
    /// A rope (or hair, `hair: true`) of particles and springs, pinned at its start.
    Rope {
        /// First node (m).
        from: Vec3,
        /// Last node (m).
        to: Vec3,
        /// Node count (≥ 2).
        nodes: usize,
        /// Stiffness of each segment (N/m).
        #[serde(default)]
        stiffness: Option<f32>,
        /// Damping of each segment (N·s/m).
        #[serde(default)]
        damping: Option<f32>,
        /// Mass of each node (kg).
        #[serde(default)]
        node_mass: Option<f32>,
        /// Pin the last node too (a bridge or a washing line).
        #[serde(default)]
        pin_end: bool,
        /// Hair: bending springs, pinned root.
        #[serde(default)]
        hair: bool,
    },
    /// A square-gridded cloth in the xz plane from `corner`, `nx` × `nz` nodes.
    Cloth {
        /// The corner node (m).
        corner: Vec3,
        /// Nodes along x.
        nx: usize,
        /// Nodes along z.
        nz: usize,
        /// Node spacing (m).
        spacing: f32,
        /// Pin the two corners of the first row (default true).
        #[serde(default = "yes")]
        pin_corners: bool,
        /// Structural, shear and bending stiffness (N/m).
        #[serde(default)]
        stiffness: Option<(f32, f32, f32)>,
        /// Mass of each node (kg).
        #[serde(default)]
        node_mass: Option<f32>,
        /// Damping of every spring (N·s/m).
        #[serde(default)]
        damping: Option<f32>,
        /// More nodes to pin, by index `iz * nx + ix` (both ends of a bridge).
        #[serde(default)]
        pin: Vec<usize>,
    },
    /// A 0.4 m jelly cube (co-rotated FEM, E = 200 kPa, ν = 0.3, 1000 kg/m³).
    Jelly {
        /// Its centre (m).
        at: Vec3,
        /// On the implicit solver.
        #[serde(default)]
        implicit: bool,
    },
    /// `n` unit boxes stacked on the ground (the ground included, not named).
    Column {
        /// Box count.
        n: usize,
    },
    /// A one-box-deep pyramid of `layers` rows of unit boxes on the ground (the ground
    /// included, not named).
    Pyramid {
        /// Rows.
        layers: usize,
    },
}

/// A joint's kind. Axes are unit vectors in each body's axes (world axes for the world side).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum JointKind {
    /// Holds the anchors together; every turn free.
    Ball,
    /// A ball joint whose turns are limited about `axis` (each body's axis as spawned, like
    /// a shoulder's): the swing, the angle between the two sides' axes, within a cone; the
    /// twist about the axis within a range; and friction resisting any turn.
    LimitedBall {
        /// The joint's axis.
        axis: Vec3,
        /// The cone's half-angle (degrees, in (0, 180)).
        #[serde(default)]
        swing: Option<f32>,
        /// The twist's range (degrees, within ±180).
        #[serde(default)]
        twist: Option<(f32, f32)>,
        /// The most torque friction gives against any turn (N·m).
        #[serde(default)]
        friction: Option<f32>,
    },
    /// A hinge about `axis`.
    Hinge {
        /// The hinge axis.
        axis: Vec3,
        /// The angle's range (degrees, within ±180).
        #[serde(default)]
        limits: Option<(f32, f32)>,
        /// A motor: target speed (rad/s) and the most torque it gives (N·m).
        #[serde(default)]
        motor: Option<(f32, f32)>,
        /// A position motor (servo): target angle (degrees), stiffness (N·m/rad), damping
        /// (N·m·s/rad) and the most torque it gives (N·m). Takes the place of `motor`.
        #[serde(default)]
        servo: Option<(f32, f32, f32, f32)>,
    },
    /// A slider along `axis`, the relative rotation held as spawned.
    Slider {
        /// The slide axis.
        axis: Vec3,
        /// The offset's range (m).
        #[serde(default)]
        limits: Option<(f32, f32)>,
        /// A motor: target speed (m/s) and the most force it gives (N).
        #[serde(default)]
        motor: Option<(f32, f32)>,
        /// A position motor (servo): target offset (m), stiffness (N/m), damping (N·s/m)
        /// and the most force it gives (N). Takes the place of `motor`.
        #[serde(default)]
        servo: Option<(f32, f32, f32, f32)>,
    },
    /// Keeps the anchors `length` apart (default: as spawned); `rope: true` lets them come
    /// closer.
    Distance {
        /// The length (m).
        #[serde(default)]
        length: Option<f32>,
        /// Slack below the length.
        #[serde(default)]
        rope: bool,
    },
    /// A weld at the relative pose as spawned.
    Fixed,
}

fn one() -> f32 {
    1.0
}

fn yes() -> bool {
    true
}

/// A collider shape, sizes in metres.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
pub enum Shape {
    /// Half extents x, y, z.
    Cuboid(f32, f32, f32),
    /// Radius.
    Ball(f32),
    /// Half height of the segment along y, radius.
    Capsule(f32, f32),
    /// Half height along y, radius.
    Cylinder(f32, f32),
}

/// A rigid body's kind.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum BodyKind {
    /// Moved by forces.
    #[default]
    Dynamic,
    /// Moved by its velocity only.
    Kinematic,
    /// Never moves.
    Static,
}

/// A velocity field.
#[derive(Deserialize, Debug, Clone, Copy, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum Field {
    /// The same velocity everywhere (m/s).
    Uniform {
        /// The velocity (m/s).
        velocity: Vec3,
    },
    /// A rigid rotation about `axis` through `center` at `rate` rad/s.
    Vortex {
        /// A point on the axis (m).
        center: Vec3,
        /// The axis direction.
        axis: Vec3,
        /// Turning rate (rad/s).
        rate: f32,
    },
}

/// `(at: 1.0, do: ..)` or `(step: 60, do: ..)`: an action of the timeline.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct TimelineEntry {
    /// When (s from the start); exactly one of `at` and `step`.
    #[serde(default)]
    pub at: Option<f64>,
    /// When (steps from the start).
    #[serde(default)]
    pub step: Option<u64>,
    /// What.
    #[serde(rename = "do")]
    pub action: Action,
}

/// What game code does at a moment. `entity` is a name or `name[i]`; a group name acts on
/// every member.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum Action {
    /// A one-shot impulse at the centre of mass (N·s).
    Impulse {
        /// Who.
        entity: String,
        /// The impulse (N·s).
        impulse: Vec3,
    },
    /// A persistent force at the centre of mass until set again (N); zero clears it.
    Force {
        /// Who.
        entity: String,
        /// The force (N).
        force: Vec3,
    },
    /// A persistent torque until set again (N·m).
    Torque {
        /// Who.
        entity: String,
        /// The torque (N·m).
        torque: Vec3,
    },
    /// Sets a hinge's or a slider's motor: target speed (rad/s or m/s) and the most torque
    /// or force it gives (N·m or N); a zero maximum switches it off.
    SetMotor {
        /// The joint.
        joint: String,
        /// Target speed (rad/s for a hinge, m/s for a slider).
        target_velocity: f32,
        /// The most torque (N·m) or force (N) it gives.
        max: f32,
    },
    /// Sets a hinge's or a slider's position motor (servo): the target (degrees for a hinge,
    /// m for a slider), stiffness (N·m/rad or N/m), damping (N·m·s/rad or N·s/m) and the
    /// most torque or force it gives (N·m or N); it takes the place of any motor.
    SetServo {
        /// The joint.
        joint: String,
        /// Target angle (degrees) or offset (m).
        target: f32,
        /// Stiffness (N·m/rad or N/m).
        stiffness: f32,
        /// Damping (N·m·s/rad or N·s/m).
        damping: f32,
        /// The most torque (N·m) or force (N) it gives.
        max: f32,
    },
    /// Sets the velocity (m/s).
    SetVelocity {
        /// Who.
        entity: String,
        /// The velocity (m/s).
        velocity: Vec3,
    },
    /// Sets the angular velocity (rad/s).
    SetAngularVelocity {
        /// Who.
        entity: String,
        /// The angular velocity (rad/s).
        angular_velocity: Vec3,
    },
    /// Moves it (m), velocity kept.
    Teleport {
        /// Who.
        entity: String,
        /// Where (m).
        to: Vec3,
    },
    /// Spawns a new named entry.
    Spawn {
        /// Its name (unique in the file).
        name: String,
        /// What.
        spawn: Spawn,
    },
    /// Despawns it.
    Despawn {
        /// Who.
        entity: String,
    },
    /// Pins a particle or rope node in place; makes a rigid body static.
    Pin {
        /// Who.
        entity: String,
    },
    /// Undoes [`Action::Pin`]: the mass it had (a particle) or dynamic again (a body).
    Release {
        /// Who.
        entity: String,
    },
    /// Sets gravity (m/s²).
    SetGravity {
        /// The new gravity (m/s²).
        gravity: Vec3,
    },
    /// Sets a body's friction coefficient.
    SetFriction {
        /// Who.
        entity: String,
        /// μ (≥ 0).
        value: f32,
    },
    /// Sets a body's restitution.
    SetRestitution {
        /// Who.
        entity: String,
        /// e (0 to 1).
        value: f32,
    },
    /// Turns an effect back on (only `Gravity` and `Sleep` switch at run time).
    Enable(PluginName),
    /// Turns an effect off (only `Gravity` and `Sleep` switch at run time).
    Disable(PluginName),
}

/// `(at: 3.0, check: ..)`, `(step: 180, check: ..)`, `(during: (1.0, 3.0), check: ..)` or
/// `(check: ..)` for the whole run.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ExpectEntry {
    /// At this time (s).
    #[serde(default)]
    pub at: Option<f64>,
    /// At this step.
    #[serde(default)]
    pub step: Option<u64>,
    /// At every step in this window (s, inclusive).
    #[serde(default)]
    pub during: Option<(f64, f64)>,
    /// What must hold.
    pub check: Check,
}

/// A quantity of one entity (its centre of mass, or a mesh's mean node).
#[derive(Deserialize, Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// x (m).
    X,
    /// y (m).
    Y,
    /// z (m).
    Z,
    /// |v| (m/s).
    Speed,
    /// vx (m/s).
    Vx,
    /// vy (m/s).
    Vy,
    /// vz (m/s).
    Vz,
    /// |ω| (rad/s).
    AngularSpeed,
}

/// What an expectation asserts. Ranges are `(min, max)`, inclusive. On a group name, the
/// position and speed checks hold for every member.
#[derive(Deserialize, Debug, Clone, PartialEq)]
#[serde(deny_unknown_fields)]
pub enum Check {
    /// Its position lies within the given ranges (m); at least one of x, y, z.
    Position {
        /// Who.
        entity: String,
        /// x range (m).
        #[serde(default)]
        x: Option<(f32, f32)>,
        /// y range (m).
        #[serde(default)]
        y: Option<(f32, f32)>,
        /// z range (m).
        #[serde(default)]
        z: Option<(f32, f32)>,
    },
    /// It is within `within` (m) of `point`.
    Near {
        /// Who.
        entity: String,
        /// Where (m).
        point: Vec3,
        /// How close (m).
        within: f32,
    },
    /// Its speed lies within bounds (m/s); at least one of min, max.
    Speed {
        /// Who.
        entity: String,
        /// Lowest speed (m/s).
        #[serde(default)]
        min: Option<f32>,
        /// Highest speed (m/s).
        #[serde(default)]
        max: Option<f32>,
    },
    /// Its spin lies within bounds (rad/s).
    AngularSpeed {
        /// Who.
        entity: String,
        /// Lowest (rad/s).
        #[serde(default)]
        min: Option<f32>,
        /// Highest (rad/s).
        #[serde(default)]
        max: Option<f32>,
    },
    /// The largest value of `quantity` over the window lies within bounds (an apex).
    Peak {
        /// Who.
        entity: String,
        /// What.
        quantity: Quantity,
        /// Lowest accepted peak.
        #[serde(default)]
        min: Option<f64>,
        /// Highest accepted peak.
        #[serde(default)]
        max: Option<f64>,
    },
    /// The world's total energy (kinetic, gravitational, spring, elastic; J) stays within
    /// `relative` × |E₀| + `absolute` of E₀, its value at the window's first check.
    Energy {
        /// Relative tolerance.
        #[serde(default)]
        relative: f64,
        /// Absolute tolerance (J).
        #[serde(default)]
        absolute: f64,
    },
    /// Linear momentum (kg·m/s) of the named entities (of the whole world without
    /// `entity`) stays within `relative` × |P₀| + `absolute` of P₀.
    Momentum {
        /// Whose; every body when absent.
        #[serde(default)]
        entity: Option<String>,
        /// Relative tolerance.
        #[serde(default)]
        relative: f64,
        /// Absolute tolerance (kg·m/s).
        #[serde(default)]
        absolute: f64,
    },
    /// The two touch at some step of the window (bodies with colliders).
    Contact {
        /// One.
        a: String,
        /// The other.
        b: String,
    },
    /// The two never touch in the window.
    NoContact {
        /// One.
        a: String,
        /// The other.
        b: String,
    },
    /// No body is quarantined in the window.
    NoQuarantine,
    /// It is quarantined in the window (a hard case caught, not flying off).
    Quarantined {
        /// Who.
        entity: String,
    },
    /// It is asleep.
    Asleep {
        /// Who.
        entity: String,
    },
    /// It is awake.
    Awake {
        /// Who.
        entity: String,
    },
    /// `quantity` matches a closed form of `t` (s) within `tolerance` (the quantity's
    /// units). The expression may use `t`, `g` (|gravity|, m/s²), `pi`, + − * / ^ and
    /// sqrt, sin, cos, tan, exp, ln, abs.
    ClosedForm {
        /// Who (one entity).
        entity: String,
        /// What.
        quantity: Quantity,
        /// The closed form, e.g. `"10 - g*t^2/2"`.
        value: String,
        /// Largest accepted |measured − closed form|.
        tolerance: f64,
    },
}
