//! How much memory a render will take, estimated from the loaded scene and
//! the settings before the first frame: what `--max-memory` (and
//! `render.max_memory`) compare against. Each part is the size of the
//! buffers it names (element counts times element sizes); the process part
//! is measured (a render of an empty-ish scene) and the load-time peaks
//! (a mesh and its copy, textures being decoded) are included, so the
//! total tracks the process's peak resident memory (see docs: measured
//! against `/usr/bin/time -v` in docs/performance notes).

use std::collections::HashSet;
use std::mem::size_of;

use glam::{Vec2, Vec3, Vec4};

use crate::raster::setup::Tri;
use crate::scene::Scene;
use crate::scene::settings::{AoMethod, Background, ShadowMethod, TextureFilter};

/// The parts of the estimate, in bytes.
#[derive(Debug, Clone, Default)]
pub struct MemoryEstimate {
    /// What each part is, and its bytes.
    pub parts: Vec<(&'static str, u64)>,
}

impl MemoryEstimate {
    /// The sum of the parts.
    pub fn total(&self) -> u64 {
        self.parts.iter().map(|p| p.1).sum()
    }
}

impl std::fmt::Display for MemoryEstimate {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", human(self.total()))?;
        let parts: Vec<String> = self
            .parts
            .iter()
            .filter(|p| p.1 > 0)
            .map(|(name, b)| format!("{name} {}", human(*b)))
            .collect();
        write!(f, " ({})", parts.join(", "))
    }
}

pub use crate::assets::input::human;

/// The process itself (code, allocator, thread stacks touched), measured
/// as the peak resident size of a 64x64 render of one triangle, and per
/// worker thread.
const PROCESS: u64 = 9 << 20;
const PER_THREAD: u64 = 512 << 10;
/// Frames whose outputs may wait for the writer at once (the batch's
/// channel of 2, plus the one being written), at most the frames rendered.
const FRAMES_IN_FLIGHT: u64 = 3;
/// BVH bytes per triangle: a 48-byte precomputed triangle, a 4-byte
/// index, about one 40-byte node, and the build's 48-byte references.
const BVH_PER_TRIANGLE: u64 = 48 + 4 + 40 + 48;
/// Per-frame vertex bytes: the transformed vertex (clip position, world
/// position and normal) and its projected corner for set-up.
const VERTEX: u64 = 64 + super::geometry::CORNER_BYTES as u64;

/// What a renderer keeps of a camera that stays (`rays::ViewCache`), for
/// a frame of `pixels`: the backdrop (`render::backdrop`), and the ground
/// view (`render::ground`, without lights: at most a spot per pixel).
fn kept_views(scene: &Scene, pixels: u64, parts: &mut Vec<(&'static str, u64)>) {
    let s = &scene.settings;
    if matches!(
        s.background,
        Background::Environment | Background::Blurred(_)
    ) && scene.environment.is_some()
    {
        parts.push(("backdrop", pixels * size_of::<Vec4>() as u64));
    }
    if scene.ground.is_some() {
        parts.push(("ground view", pixels * super::ground::SPOT_BYTES));
    }
}

/// The estimate for rendering `scene` with `threads` workers.
pub fn estimate(scene: &Scene, threads: usize) -> MemoryEstimate {
    let s = &scene.settings;
    let threads = threads.max(1) as u64;
    let mut parts = vec![("process", PROCESS + PER_THREAD * threads)];

    // Meshes: each distinct one, and during loading its source copy too.
    let mut seen = HashSet::new();
    let (mut mesh_bytes, mut tris, mut verts) = (0u64, 0u64, 0u64);
    let mut tangent_corners = 0u64;
    for m in &scene.models {
        let mesh = &m.mesh;
        verts += mesh.positions.len() as u64;
        tris += mesh.triangles.len() as u64;
        tangent_corners += mesh.tangents.len() as u64;
        if !seen.insert(std::sync::Arc::as_ptr(mesh)) {
            continue;
        }
        mesh_bytes += (mesh.positions.len() + mesh.normals.len()) as u64 * size_of::<Vec3>() as u64
            + (mesh.uvs.len() + mesh.uvs1.len()) as u64 * size_of::<Vec2>() as u64
            + (mesh.colors.len() + mesh.authored_tangents.len() + mesh.tangents.len()) as u64
                * size_of::<Vec4>() as u64
            + mesh.triangles.len() as u64 * 12;
    }
    parts.push(("meshes", mesh_bytes * 2));
    // Models playing glTF clips: the rig's source vertices, and per frame
    // in flight the posed vertices (position, normal, placement matrix
    // while posing) and tangents, and a BVH of the pose.
    let posed: u64 = scene
        .models
        .iter()
        .filter(|m| m.playback.is_some())
        .map(|m| {
            let (v, t) = (m.mesh.positions.len() as u64, m.mesh.triangles.len() as u64);
            v * (24 + 72) + 3 * t * 16 + t * BVH_PER_TRIANGLE + v * 64
        })
        .sum();
    if posed > 0 {
        parts.push(("posed models", posed * FRAMES_IN_FLIGHT.min(2)));
    }

    // Textures (4 bytes a texel), their mip chains when filtered with
    // them, and the decoding of the largest ones at once while loading.
    let texels: Vec<u64> = scene
        .textures
        .iter()
        .map(|t| t.width as u64 * t.height as u64 * 4)
        .collect();
    let tex_bytes: u64 = texels.iter().sum();
    parts.push(("textures", tex_bytes));
    if s.texture_filter >= TextureFilter::Trilinear {
        parts.push(("mip chains", tex_bytes / 3));
    }
    let mut largest = texels.clone();
    largest.sort_unstable_by(|a, b| b.cmp(a));
    // (The decoder's image and its conversion to our layout.)
    parts.push((
        "texture decoding",
        2 * largest.iter().take(threads as usize).sum::<u64>(),
    ));

    if let Some(env) = &scene.environment {
        // The image, its prefiltered chain, the background's levels and
        // the prefiltering's working set.
        let img = env.image.width as u64 * env.image.height as u64 * size_of::<Vec3>() as u64;
        parts.push(("environment", img * 2 + (2 << 20)));
    }

    let shadow_rays = s.shadows == ShadowMethod::Raytraced
        && (scene.lights.iter().any(|l| l.shadows) || !scene.emitters.is_empty());
    let sampled_env = scene.environment.as_ref().is_some_and(|e| {
        matches!(
            e.method,
            crate::scene::environment::EnvMethod::Sampled { .. }
        )
    });
    if shadow_rays || s.ao.method == AoMethod::Raytraced || sampled_env || scene.ground.is_some() {
        parts.push(("BVHs", tris * BVH_PER_TRIANGLE));
    }

    // Per frame: the (supersampled) frame, the resolved one, per worker a
    // band's samples, the set-up triangles and transformed vertices.
    let k = s.ssaa.max(1) as u64;
    let (w, h) = (s.width as u64, s.height as u64);
    let ao = if s.ao.method != AoMethod::Off { 4 } else { 0 };
    let px = size_of::<Vec4>() as u64 + 4 + ao;
    let mut frame = w * k * h * k * px;
    if k > 1 {
        frame += w * h * px;
    }
    parts.push(("frame", frame));
    kept_views(scene, w * k * h * k, &mut parts);
    if s.ao.method != AoMethod::Off {
        let g = size_of::<crate::shade::ao::GPixel>() as u64;
        parts.push(("AO buffers", w * k * h * k * (g + 4)));
    }
    let samples = s.msaa.max(1) as u64;
    let band_rows = crate::raster::bin::BAND_ROWS as u64;
    parts.push((
        "bands",
        threads * w * k * band_rows * samples * (4 + 4 + size_of::<Vec4>() as u64),
    ));
    // Set-up triangles twice (each chunk's list, and the frame's list they
    // are gathered into: a 1M-triangle mesh peaked at 1.16 times an
    // estimate that counted them once), a bin entry each, the vertices,
    // and the tangents turned with the model, one per triangle corner.
    parts.push((
        "triangles",
        tris * (2 * size_of::<Tri>() as u64 + 8)
            + verts * VERTEX
            + tangent_corners * size_of::<Vec4>() as u64,
    ));
    if matches!(s.shadows, ShadowMethod::Hard | ShadowMethod::Pcf) {
        let side = s.shadow_map_size as u64 + 4;
        let maps: u64 = scene
            .lights
            .iter()
            .filter(|l| l.shadows)
            .map(|l| match l.kind {
                crate::scene::light::LightKind::Point { .. } => 6,
                _ => 1,
            })
            .sum();
        parts.push(("shadow maps", maps * side * side * 4));
    }
    let out = &scene.output;
    let per_output = w * h * (4 + if out.depth { 4 } else { 0 } + if out.ao { 4 } else { 0 });
    let frames =
        (scene.animation.frames as u64 * scene.cameras.len() as u64).clamp(1, FRAMES_IN_FLIGHT);
    parts.push(("outputs in flight", frames * per_output));
    if out.gif.is_some() {
        // Palette training (2^21 pixels sampled over the frames, as RGB
        // and RGBA), then per worker a frame decoded for mapping with its
        // dithering errors, and a batch of 8 mapped frames.
        parts.push(("GIF", (1u64 << 21) * 7 + threads * w * h * 8 + 8 * w * h));
    }
    MemoryEstimate { parts }
}
