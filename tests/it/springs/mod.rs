//! Springs, chains and spring meshes: forces, stability limits, warnings and the implicit solves.

mod a_stiff_rope_is_rescued_whole;
mod chain;
mod dampers_are_not_runaways;
mod damping_limit;
mod default_builders_stable;
mod force_law_and_chains;
mod implicit_entities;
mod implicit_meshes;
mod local_substeps;
mod rescue_keeps_the_motion;
mod stiff_springs_warned_and_caught;
