//! Tetrahedral soft bodies: strain models, meshes, implicit solves, attachments and contact.

mod attach;
mod contact_two_way;
mod crushed_starts_recover;
mod implicit;
mod mesh_files;
mod meshes_changed_mid_run;
mod soft_body;
mod stable_at_the_defaults;
mod strain;
