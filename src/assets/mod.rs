//! Asset loaders: meshes and materials from OBJ/MTL, glTF, STL, PLY, FBX,
//! USD and 3MF, textures from images.

pub(crate) mod accessor;
pub(crate) mod dds;
pub(crate) mod draco;
pub mod environment;
pub(crate) mod fbx;
pub(crate) mod gltf;
pub(crate) mod guard;
pub mod input;
pub mod keyframes;
pub(crate) mod ktx2;
pub mod mesh;
pub(crate) mod meshopt;
pub mod mip;
pub(crate) mod obj;
pub(crate) mod ply;
pub mod rig;
pub(crate) mod stl;
pub(crate) mod text;
pub mod texture;
pub(crate) mod threemf;
pub(crate) mod usd;

/// The model file extensions softraster reads (case-insensitive).
pub const MODEL_EXTENSIONS: [&str; 11] = [
    "gltf", "glb", "obj", "stl", "ply", "fbx", "usd", "usda", "usdc", "usdz", "3mf",
];

/// Whether `ext` (without the dot) is a model file's.
pub fn is_model_extension(ext: &str) -> bool {
    MODEL_EXTENSIONS.iter().any(|x| ext.eq_ignore_ascii_case(x))
}

/// The model extensions as a message lists them: ".gltf, .glb, ...".
pub fn model_extensions_listed() -> String {
    format!(".{}", MODEL_EXTENSIONS.join(", ."))
}
