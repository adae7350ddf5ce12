//! The renderer's settings, as `scene::assemble` makes them from the file
//! (`scene::desc`) and its defaults: the types every stage reads. The file's
//! spelling of a value is `desc`'s business; a change to the file format
//! stops at `build`.
//!
//! Stage-specific vocabularies live with their stage and are re-exported
//! here: `CullMode` and `DepthMode` (raster), `TextureFilter` and
//! `AddressMode` (texture sampling).

use std::path::PathBuf;

use glam::Vec3;

pub use crate::assets::texture::{AddressMode, TextureFilter};
pub use crate::raster::{CullMode, DepthMode};

/// `render.shading`: which shading model, or which data view, a frame shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShadingMode {
    /// Each material in its file's model: Blinn-Phong for MTL, pbr for glTF.
    #[default]
    Auto,
    /// Blinn-Phong for every material.
    BlinnPhong,
    /// glTF 2.0 metallic-roughness (appendix B BRDF) for every material.
    Pbr,
    /// Blinn-Phong with the triangle's plane normal.
    Flat,
    /// Blinn-Phong light summed at the vertices and interpolated.
    Gouraud,
    /// Surface color (and emission) without light.
    Unlit,
    /// Data view: the shading normal as n * 0.5 + 0.5.
    Normals,
    /// Data view: view depth, white (near) to black (far).
    Depth,
    /// Data view: anti-aliased triangle edges.
    Wireframe,
}

impl ShadingMode {
    /// The data views write values, not radiance: no tone map, no sRGB.
    pub fn is_data_view(self) -> bool {
        matches!(
            self,
            ShadingMode::Normals | ShadingMode::Depth | ShadingMode::Wireframe
        )
    }
}

/// `render.shadows`: how lights with `shadows = true` cast them.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ShadowMethod {
    /// No shadows.
    Off,
    /// One texel of a shadow map per lookup.
    Hard,
    /// A 3x3-texel area-weighted box of a shadow map.
    Pcf,
    /// A ray towards the light through the scene's BVHs: exact. The default
    /// (faster than 2048 maps on every charted scene, docs/chart.md).
    #[default]
    Raytraced,
}

/// `render.ao.method`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum AoMethod {
    #[default]
    /// No ambient occlusion.
    Off,
    /// Screen-space ground-truth AO (GTAO: horizons per slice of the depth
    /// buffer); the file calls it `ssao`.
    Gtao,
    /// Cosine-weighted rays through the scene's BVHs: the reference.
    Raytraced,
}

/// `render.tonemap`: linear radiance to display range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Tonemap {
    #[default]
    /// Clamped to 0..1.
    Clamp,
    /// x / (1 + x).
    Reinhard,
    /// Narkowicz's fit of the ACES filmic curve.
    Aces,
    /// three.js's `ACESFilmicToneMapping` (also model-viewer's and
    /// Babylon's ACES): Stephen Hill's fit of the ACES RRT and ODT, the
    /// radiance first scaled by 1/0.6 as three.js does.
    AcesHill,
    /// Khronos PBR Neutral: colours under 0.76 unchanged.
    PbrNeutral,
    /// AgX: a filmic curve that desaturates highlights toward white.
    Agx,
}

/// `output.background`: linear RGB, transparent (RGBA output), or the
/// scene's environment seen through the camera, sharp or blurred.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Background {
    /// A colour, linear RGB.
    Color(Vec3),
    /// Alpha 0: the PNG gets an alpha channel.
    Transparent,
    /// The environment through the camera, sharp.
    Environment,
    /// The environment prefiltered at roughness `output.background_blur`.
    Blurred(f32),
}

/// `output.gif_dither`: how GIF frames are mapped to the shared palette.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum GifDither {
    /// Nearest palette color.
    #[default]
    None,
    /// An 8x8 Bayer pattern: stable from frame to frame where the image is.
    Ordered,
    /// Error diffusion: smoothest gradients, but its noise moves with the
    /// image.
    FloydSteinberg,
}

/// Everything that decides how a frame is rasterized and shaded.
#[derive(Debug, Clone, PartialEq)]
pub struct RenderSettings {
    /// Output width in pixels.
    pub width: u32,
    /// Output height in pixels.
    pub height: u32,
    /// The shading model.
    pub shading: ShadingMode,
    /// How textures are filtered.
    pub texture_filter: TextureFilter,
    /// The largest anisotropy `anisotropic` filtering takes (default 16).
    pub max_anisotropy: f32,
    /// Specular anti-aliasing: metallic-roughness lobes widened by the
    /// normal map's change across a pixel (Tokuyoshi and Kaplanyan).
    pub specular_aa: bool,
    /// How texture coordinates outside 0..1 wrap.
    pub address: AddressMode,
    /// Which faces are culled (`auto`: closed meshes' back faces).
    pub cull: CullMode,
    /// How depth is stored (reverse-Z by default).
    pub depth: DepthMode,
    /// Linear radiance to display range.
    pub tonemap: Tonemap,
    /// Stops (`2^exposure` scales the radiance before the tone map); 0
    /// with `auto_exposure`.
    pub exposure: f32,
    /// `render.exposure = "auto"`: the renderer computes one exposure for
    /// the whole sequence (`Renderer::exposure`).
    pub auto_exposure: bool,
    /// What shows where no model is.
    pub background: Background,
    /// Ambient light, linear RGB (0 under an environment).
    pub ambient: Vec3,
    /// How lights with `shadows = true` cast them (default raytraced; pcf
    /// when the scene sets a shadow-map key without a method).
    pub shadows: ShadowMethod,
    /// Shadow map size in texels, per side (default 2048).
    pub shadow_map_size: u32,
    /// Shadow-map bias.
    pub shadow_bias: ShadowBias,
    /// Ambient occlusion.
    pub ao: AoSettings,
    /// Samples per pixel: 1, 2, 4, 8 or 16 (standard D3D positions).
    pub msaa: u32,
    /// Supersampling factor per axis (1: off).
    pub ssaa: u32,
    /// `render.max_memory` (bytes): refuse to render when the estimate
    /// (`render::memory`) exceeds it. `--max-memory` wins.
    pub max_memory: Option<u64>,
    /// `render.sandbox` (or `--sandbox`): reads stay in the scene's folder.
    pub sandbox: bool,
    /// Output pixels across a point and a line.
    pub point_size: f32,
    /// Output pixels across a line.
    pub line_width: f32,
}

/// Shadow-map bias, in texels of the map at the receiver.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadowBias {
    /// Depth bias (default 1).
    pub constant: f32,
    /// Depth bias times the tangent of the angle between normal and light
    /// (default 0.5; the tangent is capped at 10).
    pub slope: f32,
    /// Lookup point moved along the geometric normal, times the sine of
    /// the angle between normal and light (default 1).
    pub normal: f32,
}

impl Default for ShadowBias {
    fn default() -> ShadowBias {
        ShadowBias {
            constant: 1.0,
            slope: 0.5,
            normal: 1.0,
        }
    }
}

/// `render.ao`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AoSettings {
    /// Off, screen-space (GTAO) or ray-traced.
    pub method: AoMethod,
    /// Occluders within this distance count; None (raytraced only): rays of
    /// unbounded length. SSAO without a radius uses a fifth of the scene's
    /// bounding radius.
    pub radius: Option<f32>,
    /// Rays per pixel (raytraced) or depth-buffer reads per pixel (ssao).
    pub samples: u32,
}

/// `output.video_quality`: a quality (1 to 100, the default 75) that maps
/// to a constant quantizer, or a target bitrate.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum VideoQuality {
    /// 1 (smallest file) to 100 (best picture).
    Quality(u8),
    /// Bits per second.
    Bitrate(u32),
}

impl Default for VideoQuality {
    fn default() -> Self {
        VideoQuality::Quality(75)
    }
}

impl VideoQuality {
    /// H.264 quantizer of a quality: 100 -> 10, 75 -> 20, 1 -> 51.
    pub fn qp(q: u8) -> u8 {
        let q = q.clamp(1, 100) as f32;
        (51.0 - (q - 1.0) * 41.0 / 99.0).round() as u8
    }

    /// Parses `video_quality`'s string form: a bitrate such as "2500k",
    /// "4M" or "800000" (bits per second).
    pub fn parse_bitrate(s: &str) -> Option<VideoQuality> {
        let s = s.trim();
        let (num, scale) = match s.as_bytes().last()? {
            b'k' | b'K' => (&s[..s.len() - 1], 1e3),
            b'm' | b'M' => (&s[..s.len() - 1], 1e6),
            _ => (s, 1.0),
        };
        let v = num.trim().parse::<f64>().ok()? * scale;
        (v.is_finite() && (10_000.0..=200e6).contains(&v))
            .then_some(VideoQuality::Bitrate(v as u32))
    }
}

/// Largest frame OpenH264 encodes (level 5.2).
const MAX_LONG_SIDE: u32 = 3840;
const MAX_SHORT_SIDE: u32 = 2160;

/// Checks that frames of this size can be encoded (before any rendering).
pub fn check_video_size(width: u32, height: u32) -> Result<(), String> {
    let (w, h) = (width.next_multiple_of(2), height.next_multiple_of(2));
    if w.max(h) > MAX_LONG_SIDE || w.min(h) > MAX_SHORT_SIDE {
        return Err(format!(
            "a video frame may be at most 3840x2160 (or 2160x3840); these frames are {width}x{height}"
        ));
    }
    Ok(())
}

/// `[output]`: which files each frame writes, where, and the GIF and
/// video.
#[derive(Debug, Clone, PartialEq)]
pub struct OutputSettings {
    /// The output folder (`--out` wins).
    pub dir: PathBuf,
    /// File stem pattern with `{scene}`, `{camera}`, `{frame}` (`{frame:04}`
    /// pads with zeros).
    pub name: String,
    /// Whether the PNG is written.
    pub color: bool,
    /// `<name>_depth.exr`, channel `Z`.
    pub depth: bool,
    /// `<name>_ao.exr`, channel `AO`.
    pub ao: bool,
    /// The GIF's file name (in `dir`; `{camera}`, or `_<camera>` added
    /// before the extension when the scene has several cameras).
    pub gif: Option<String>,
    /// GIF frame delay in milliseconds.
    pub gif_delay_ms: u32,
    /// GIF dithering.
    pub gif_dither: GifDither,
    /// The video's file name (in `dir`; per camera like the GIF).
    pub video: Option<String>,
    /// Video frames per second.
    pub video_fps: f64,
    /// Video quality or bit rate.
    pub video_quality: VideoQuality,
    /// `{stem}_normal.exr`, channels `N.X N.Y N.Z` (world, unit).
    pub normal: bool,
    /// `{stem}_albedo.exr`, channels `albedo.R albedo.G albedo.B` (linear).
    pub albedo: bool,
    /// `{stem}_position.exr`, channels `P.X P.Y P.Z` (world).
    pub position: bool,
    /// `{stem}_id.exr`, UINT channels `object_id` and `material_id`, and
    /// `{scene}_ids.json` naming them.
    pub id: bool,
}

impl OutputSettings {
    /// Whether frames need the data passes (`Frame::aov`).
    pub fn writes_aovs(&self) -> bool {
        self.normal || self.albedo || self.position || self.id
    }
}
