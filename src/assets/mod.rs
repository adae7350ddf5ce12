//! Asset loaders: meshes and materials from OBJ/MTL and glTF, textures from
//! images.

pub mod environment;
pub mod gltf;
pub mod mesh;
pub mod mip;
pub mod obj;
pub mod texture;
