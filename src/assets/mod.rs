//! Asset loaders: meshes and materials from OBJ/MTL, glTF, STL, PLY, FBX,
//! USD and 3MF, textures from images.

pub mod accessor;
pub mod dds;
pub mod draco;
pub mod environment;
pub mod fbx;
pub mod gltf;
pub mod guard;
pub mod input;
pub mod keyframes;
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
pub mod threemf;
pub mod usd;

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
