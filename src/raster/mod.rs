//! The raster pipeline's stages, in the order data flows through them:
//! `clip` (clip-space polygons) -> `setup` (fixed-point edges, culling) ->
//! `bin` (per-tile triangle lists) -> `coverage` (depth-tested visibility per
//! tile) -> `interp` (perspective-correct barycentrics for shading). Nothing
//! here knows about materials, lights or files.

pub mod bin;
pub mod clip;
pub mod coverage;
pub mod interp;
pub mod setup;

/// Which triangles setup discards by their winding on screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CullMode {
    /// Counter-clockwise triangles face the camera; clockwise ones go.
    #[default]
    Back,
    Front,
    None,
}

/// How view distance maps to stored depth.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DepthMode {
    /// Near 1, far 0, in float: precision follows distance (the default).
    #[default]
    ReverseZ,
    /// Near 0, far 1 (OpenGL-style, for comparison).
    Standard,
}
