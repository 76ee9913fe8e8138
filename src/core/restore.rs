//! Resources the plugins install, put back if game code removes them.
//!
//! Every system reads its settings and state as resources; one that is missing would fail
//! the system's parameter check, which panics. Each plugin installs its resources through
//! `init`, which also remembers how to make them; at the start of every step,
//! [`PhysicsSystems::Restore`](crate::core::schedule::PhysicsSystems::Restore) re-creates any that were
//! removed, at their defaults, and writes one [`ResourceRestored`] message for each. A
//! removed state resource ([`crate::collision::Contacts`], the broad phase) starts afresh: contacts are
//! found again and their warm-start impulses are lost for a step.

use bevy_ecs::message::Messages;
use bevy_ecs::prelude::*;

/// Written when a physics resource was missing at the start of a step and was re-created
/// at its default.
#[derive(Message, Debug, Clone, Copy, PartialEq, Eq)]
pub struct ResourceRestored {
    /// The resource's type name.
    pub name: &'static str,
}

/// Written when a settings field held a value the solver cannot use (NaN, negative) and was
/// put back to its default.
#[derive(Message, Debug, Clone, Copy, PartialEq)]
pub struct InvalidSetting {
    /// The resource's name, e.g. `"ContactSettings"`.
    pub resource: &'static str,
    /// The field.
    pub field: &'static str,
    /// The rejected value.
    pub value: f32,
}

/// Present while a snapshot writes its entities: insert hooks that check other entities
/// (a spring's ends) wait, since the entities are written in storage order and an end may
/// come after the spring; the restore checks them once everything is written.
#[derive(Resource, Default)]
pub(crate) struct Restoring;

/// How to re-create each installed resource.
#[derive(Resource, Default)]
pub(crate) struct Restorers(Vec<fn(&mut World) -> Option<&'static str>>);

fn restore<T: Resource + Default>(world: &mut World) -> Option<&'static str> {
    if world.contains_resource::<T>() {
        return None;
    }
    world.init_resource::<T>();
    Some(std::any::type_name::<T>())
}

/// Inserts `T` at its default unless present, and re-creates it whenever it goes missing.
pub(crate) fn init<T: Resource + Default>(world: &mut World) {
    world.init_resource::<T>();
    let mut restorers = world.get_resource_or_init::<Restorers>();
    let f = restore::<T> as fn(&mut World) -> Option<&'static str>;
    if !restorers.0.contains(&f) {
        restorers.0.push(f);
    }
}

/// Re-creates every missing resource (see the module docs).
pub(crate) fn restore_resources(world: &mut World) {
    if !world.contains_resource::<Restorers>() {
        return;
    }
    // No allocation in the common case: nothing is missing.
    let restored = world.resource_scope(|world, restorers: Mut<Restorers>| {
        let mut restored = Vec::new();
        for f in &restorers.0 {
            if let Some(name) = f(world) {
                restored.push(name);
            }
        }
        restored
    });
    if !restored.is_empty() {
        restore::<Messages<ResourceRestored>>(world);
        for name in restored {
            world.write_message(ResourceRestored { name });
        }
    }
}
