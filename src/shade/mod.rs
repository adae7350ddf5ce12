//! Shading: what color a visible surface point gets, per `render.shading`.
//! Shading reads the scene (materials, lights) and never writes to it.

pub mod agx;
pub mod ao;
pub mod blinn_phong;
pub mod env;
pub mod ggx;
pub mod gouraud;
pub mod iridescence;
pub mod lanes;
pub mod light;
pub mod pbr;
pub mod refraction;
pub mod shadow;
pub mod sheen;
pub mod soft_shadow;
pub mod tonemap;

use glam::{Vec2, Vec3, Vec4};

use crate::assets::texture::{Filtering, Gradients, Level, TextureRef};
use crate::scene::material::NormalMap;
use crate::scene::settings::{AddressMode, Background, ShadingMode, TextureFilter};
use crate::scene::{Light, Material};
use crate::simd::{Lane, V3};

/// Everything about the frame that shading needs, fixed for the frame.
pub struct ShadeContext<'a> {
    pub mode: ShadingMode,
    pub lights: &'a [Light],
    pub ambient: Vec3,
    pub eye: Vec3,
    /// Camera forward (unit); the view vector of orthographic cameras.
    pub forward: Vec3,
    pub orthographic: bool,
    pub filter: TextureFilter,
    pub max_anisotropy: f32,
    /// `render.specular_aa`.
    pub specular_aa: bool,
    pub address: AddressMode,
    /// Per texture id: the mip chain (levels 1..) this frame may read, or
    /// None where the frame never minifies the texture (level 0 only).
    pub mips: &'a [Option<&'a [Level]>],
    /// View-depth range mapped to white..black by the `depth` view.
    pub depth_range: (f32, f32),
    /// This frame's shadow maps or ray tracer.
    pub shadows: &'a shadow::Shadows<'a>,
    /// Image-based lighting, when the scene has an environment.
    pub env: Option<&'a env::EnvLight>,
    /// `method = "sampled"`: the environment's sampler, the frame's rays,
    /// its emissive triangles and the sample count; replaces the
    /// prefiltered light of `env`.
    pub env_sampled: Option<env::sampled::Sampled<'a>>,
    /// `environment.reflections` under the prefiltered method: the rays
    /// along the specular lobes' dominant directions.
    pub env_reflections: Option<env::reflect::Reflections<'a>>,
    /// Rendered pixels per output pixel along an axis (the supersampling
    /// factor): wireframe lines keep their width in output pixels.
    pub pixel_scale: f32,
    /// The shaded opaque frame that transmissive surfaces refract
    /// (`refraction`), set once the frame's opaque surfaces are shaded;
    /// empty until then and in frames without transmission.
    pub refraction: std::sync::OnceLock<refraction::OpaqueFrame>,
}

/// Whether shading mode `mode` shades a point of `m` with
/// metallic-roughness.
pub(crate) fn shades_pbr(mode: ShadingMode, m: &Material) -> bool {
    crate::scene::material::shades_pbr(mode, m)
}

impl ShadeContext<'_> {
    /// Unit vector from `p` towards the eye.
    #[inline]
    pub fn view_vector(&self, p: Vec3) -> Vec3 {
        if self.orthographic {
            -self.forward
        } else {
            (self.eye - p).normalize_or(-self.forward)
        }
    }

    /// Whether a point of `m` is shaded with metallic-roughness.
    pub(crate) fn shades_pbr(&self, m: &Material) -> bool {
        shades_pbr(self.mode, m)
    }

    /// Opacity of material `m` at a point with texture coordinates `uv`
    /// (both sets; None where the mesh has none) and vertex colour
    /// `color`, its maps read at level 0 (`opacity_of`): the alpha test
    /// of cutout materials, per sample.
    pub fn opacity_at(&self, m: &Material, uv: [Option<Vec2>; 2], color: Vec4) -> f32 {
        let rgba = |t: &TextureRef| {
            let uv = uv[(t.texcoord as usize).min(1)]?;
            let f = Filtering {
                filter: self.filter,
                max_anisotropy: self.max_anisotropy,
                mips: self.mips.get(t.texture.id).copied().flatten(),
            };
            let c = t.sample_grad(uv, Gradients::ZERO, self.address, f);
            Some((V3::from(c.truncate()), c.w))
        };
        self.opacity_of(m, rgba, color.w)
    }

    /// Opacity at the lanes' points: d (glTF: the base color's alpha)
    /// times map_d (its alpha, or red without alpha) times the alpha of
    /// map_kd (glTF: of the base color texture) times the vertex colours'
    /// alpha `alpha`, reading maps through `rgba` (`Fetch::rgba`).
    pub(crate) fn opacity_of<L: Lane>(
        &self,
        m: &Material,
        mut rgba: impl FnMut(&TextureRef) -> Option<(V3<L>, L)>,
        alpha: L,
    ) -> L {
        let mut a = L::splat(m.d) * alpha;
        if let Some(t) = &m.map_d
            && let Some((c, w)) = rgba(t)
        {
            a = a * if t.texture.has_alpha { w } else { c.x };
        }
        if let Some(t) = &m.map_kd
            && t.texture.has_alpha
            && let Some((_, w)) = rgba(t)
        {
            a = a * w;
        }
        a
    }
}

/// The most `Fetch::normal_spread` gives: each axis's squared change is
/// counted up to a turn of 60 degrees (1), beyond which it is a seam.
pub(crate) const MAX_SPREAD: f32 = 2.0;

/// Where shading code (written once over the lane type `L`) reads a
/// material's texels and perturbs its normals: a lane call's through its
/// prepared maps (`shade::lanes`).
pub(crate) trait Fetch<L: Lane> {
    /// Red, green, blue and alpha of `t` at the lanes' points; None where
    /// the mesh has no coordinates of its set (the map then counts as 1).
    fn rgba(&mut self, t: &TextureRef) -> Option<(V3<L>, L)>;

    /// The lanes' interpolated normals perturbed by `map`, unit.
    fn normal(&mut self, map: &NormalMap) -> V3<L>;

    /// How far the normals `n` that `map` gives (`normal`) turn across
    /// a pixel: the squared lengths of their changes one pixel's step
    /// along u and along v, summed (0 where not measured); at most
    /// `MAX_SPREAD` (or NaN).
    fn normal_spread(&mut self, map: &NormalMap, n: V3<L>) -> L {
        let _ = (map, n);
        L::splat(0.0)
    }

    /// The normals `map` gives at four points spread over each lane's
    /// pixel (a rotated grid, a quarter of a pixel's step from the middle
    /// along u and v): what the pixel averages, for `sampled` to
    /// integrate. None where `normal_spread` measures nothing.
    fn normal_samples(&mut self, map: &NormalMap) -> Option<[V3<L>; 4]> {
        let _ = map;
        None
    }

    /// The lanes' interpolated tangents and their bitangent signs, where
    /// the mesh has them.
    fn tangents(&self) -> Option<(V3<L>, L)> {
        None
    }

    /// Red, green and blue of `t` (`rgba`).
    #[inline(always)]
    fn rgb(&mut self, t: &TextureRef) -> Option<V3<L>> {
        self.rgba(t).map(|c| c.0)
    }

    /// `rgb` of an optional map.
    #[inline(always)]
    fn rgb_of(&mut self, t: &Option<TextureRef>) -> Option<V3<L>> {
        t.as_ref().and_then(|t| self.rgb(t))
    }

    /// `rgba` of an optional map.
    #[inline(always)]
    fn rgba_of(&mut self, t: &Option<TextureRef>) -> Option<(V3<L>, L)> {
        t.as_ref().and_then(|t| self.rgba(t))
    }
}

/// Background pixel: linear color with alpha (0 for transparent); the
/// environment backgrounds vary per pixel (the renderer looks them up
/// along each pixel's ray) and are opaque black here.
pub fn background(bg: Background) -> Vec4 {
    match bg {
        Background::Color(c) => c.extend(1.0),
        Background::Transparent => Vec4::ZERO,
        Background::Environment | Background::Blurred(_) => Vec4::W,
    }
}

/// A frame's shading context for unit tests: no lights, no environment,
/// trilinear filtering.
#[cfg(test)]
pub(crate) mod testing {
    use super::*;

    pub fn context<'a>(shadows: &'a shadow::Shadows<'a>, mode: ShadingMode) -> ShadeContext<'a> {
        ShadeContext {
            mode,
            lights: &[],
            ambient: Vec3::ZERO,
            eye: Vec3::Z,
            forward: -Vec3::Z,
            orthographic: false,
            filter: TextureFilter::Trilinear,
            max_anisotropy: 16.0,
            specular_aa: true,
            address: AddressMode::Repeat,
            mips: &[],
            depth_range: (0.0, 1.0),
            shadows,
            env: None,
            env_sampled: None,
            env_reflections: None,
            pixel_scale: 1.0,
            refraction: Default::default(),
        }
    }
}
