//! The raster pipeline's stages, in the order data flows through them:
//! `clip` (clip-space polygons) -> `setup` (fixed-point edges, culling) ->
//! `bin` (per-tile triangle lists) -> `coverage` (depth-tested visibility per
//! tile) -> `interp` (perspective-correct barycentrics for shading). Nothing
//! here knows about materials, lights or files.

pub mod bin;
pub mod clip;
pub mod coverage;
pub mod interp;
#[cfg(test)]
mod known_answers;
pub mod setup;

/// Which triangles setup discards by their winding on screen.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum CullMode {
    /// Back for closed meshes and glTF materials that are not doubleSided,
    /// None for the rest (the scene decides per draw; see `resolve`).
    #[default]
    Auto,
    /// Counter-clockwise triangles face the camera; clockwise ones go.
    Back,
    /// Counter-clockwise triangles go; clockwise ones stay (the inside of
    /// a closed mesh shows).
    Front,
    /// Both windings are drawn.
    None,
}

impl CullMode {
    /// The mode for one draw under `Auto`: formats that state sidedness
    /// (glTF's `doubleSided`) are taken at their word; for the others
    /// (OBJ, STL, PLY) a closed mesh, whose back faces can never be seen,
    /// is culled and an open one is drawn two-sided.
    pub fn resolve(self, double_sided: bool, states_sidedness: bool, closed: bool) -> CullMode {
        if double_sided {
            return CullMode::None;
        }
        match self {
            CullMode::Auto if states_sidedness || closed => CullMode::Back,
            CullMode::Auto => CullMode::None,
            m => m,
        }
    }
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
