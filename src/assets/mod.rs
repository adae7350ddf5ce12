//! Asset loaders: meshes and materials from OBJ/MTL, textures from images.

pub mod mesh;
pub mod mip;
pub mod obj;
pub mod texture;
