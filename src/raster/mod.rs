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
