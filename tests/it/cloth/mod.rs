//! Cloth: builders, wind, strain limiting, collisions and the implicit path.

mod meshes_and_drapes;
mod nothing_passes;
