//! Asset loaders: meshes and materials from OBJ/MTL, glTF, STL and PLY,
//! textures from images.

pub mod accessor;
pub mod clip;
pub mod dds;
pub mod draco;
pub mod environment;
pub mod fbx;
pub mod gltf;
pub mod gltf_pose;
pub mod input;
pub mod ktx2;
pub mod mesh;
pub mod meshopt;
pub mod mip;
pub mod obj;
pub mod ply;
pub mod rig;
pub mod stl;
pub mod text;
pub mod texture;
pub mod texture_cache;
