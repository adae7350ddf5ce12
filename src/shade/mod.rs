//! Shading: what color a visible surface point gets, per `render.shading`.
//! Shading reads the scene (materials, lights) and never writes to it.

pub mod ao;
pub mod blinn_phong;
pub mod env;
pub mod gouraud;
pub mod iridescence;
pub mod lanes;
pub mod light;
pub mod pbr;
pub mod shadow;
pub mod sheen;
pub mod tonemap;

use std::cell::Cell;

use glam::{Mat3, Vec2, Vec3, Vec4};

use crate::assets::texture::{
    Filtering, Footprint, Gradients, Level, TextureFilter as Filter, TextureRef,
};
use crate::scene::material::{Native, NormalMap, NormalSpace};
use crate::scene::settings::{AddressMode, Background, ShadingMode, TextureFilter};
use crate::scene::{Light, Material};
use crate::simd::{Lane, V3};
use lanes::Lanes;
use light::LightMask;
use pbr::PbrColor;

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
    /// `method = "sampled"`: the environment's sampler, the frame's rays and
    /// the sample count; replaces the prefiltered light of `env`.
    pub env_sampled: Option<(
        &'a env::sampled::EnvSampler,
        &'a crate::raytrace::Tracer<'a>,
        u32,
    )>,
    /// Rendered pixels per output pixel along an axis (the supersampling
    /// factor): wireframe lines keep their width in output pixels.
    pub pixel_scale: f32,
}

/// Texture coordinates of a point in both sets (None where the mesh has
/// none), with their screen-space derivatives.
#[derive(Debug, Clone, Default)]
pub struct TexCoords {
    pub uv: [Option<Vec2>; 2],
    pub grads: [Gradients; 2],
    /// Per set, the last filter footprint computed and the texture size it
    /// is for: the maps of a material mostly share a size, and then one
    /// footprint (level of detail, probes) serves them all.
    footprint: [Cell<Option<SizedFootprint>>; 2],
}

/// A footprint and the texture size (width, height) it was computed for.
pub type SizedFootprint = ((u32, u32), Footprint);

impl TexCoords {
    pub fn new(uv: [Option<Vec2>; 2], grads: [Gradients; 2]) -> TexCoords {
        TexCoords {
            uv,
            grads,
            footprint: Default::default(),
        }
    }

    /// With footprints already computed for these derivatives (by another
    /// pixel of the same quad and triangle).
    pub fn with_footprints(
        uv: [Option<Vec2>; 2],
        grads: [Gradients; 2],
        footprints: [Option<SizedFootprint>; 2],
    ) -> TexCoords {
        TexCoords {
            uv,
            grads,
            footprint: footprints.map(Cell::new),
        }
    }

    /// The footprints computed so far (for the quad's other pixels).
    pub fn footprints(&self) -> [Option<SizedFootprint>; 2] {
        [self.footprint[0].get(), self.footprint[1].get()]
    }

    /// Set 0 only.
    pub fn single(uv: Option<Vec2>, grads: Gradients) -> TexCoords {
        TexCoords::new([uv, None], [grads, Gradients::default()])
    }
}

/// A visible point, interpolated.
pub struct Surface<'a> {
    pub material: &'a Material,
    pub position: Vec3,
    /// Unit shading normal, facing the side the camera sees.
    pub normal: Vec3,
    /// Interpolated vertex normal as stored (for the `normals` view).
    pub raw_normal: Vec3,
    /// Texture coordinates and their derivatives along screen x and y.
    pub tc: TexCoords,
    /// Linear RGBA vertex color (1 without one).
    pub color: Vec4,
    /// Interpolated world-space tangent and bitangent sign (tangent-space
    /// normal and bump maps).
    pub tangent: Option<Vec4>,
    /// Object to world for normals (object-space normal maps).
    pub normal_from_object: Mat3,
    /// Distance along the view axis.
    pub view_depth: f32,
    /// Gouraud: interpolated per-vertex light sums (diffuse, specular).
    pub vertex_light: Option<(Vec3, Vec3)>,
    /// Wireframe: distance to the nearest edge of the triangle, in pixels.
    pub edge_distance: f32,
    /// Unit normal of the triangle's plane, on the side the camera sees
    /// (shadow lookups and their bias).
    pub geo_normal: Vec3,
    /// Ambient occlusion at the point (1: unoccluded), multiplying the
    /// ambient term.
    pub ao: f32,
    /// The lights that may reach the point (its tile's, `LightMask::ALL`
    /// without culling); the others give it nothing.
    pub lights: LightMask,
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

    /// Linear RGB (or display values for the data views) of a surface point.
    pub fn shade(&self, s: &Surface) -> Vec3 {
        // KHR_materials_unlit: the base colour, in every lit mode.
        if s.material.unlit && !self.mode.is_data_view() {
            return self.pbr_color_at(s).base.into();
        }
        let f = Lanes::of(s);
        let mut fetch = One { ctx: self, s };
        match self.mode {
            // The shading normal (normal and bump maps applied), world space.
            ShadingMode::Normals => self.mapped_normal(s) * 0.5 + Vec3::splat(0.5),
            ShadingMode::Depth => {
                let (lo, hi) = self.depth_range;
                Vec3::splat(1.0 - ((s.view_depth - lo) / (hi - lo)).clamp(0.0, 1.0))
            }
            ShadingMode::Wireframe => {
                // Lines two output pixels wide centered on the edges (each
                // triangle draws its half), box-filtered: the fraction of
                // a pixel at distance d that lies within one pixel of the
                // edge is clamp(1.5 - d). With MSAA the silhouettes are
                // also filtered by sample coverage.
                let d = s.edge_distance / self.pixel_scale;
                let a = (1.5 - d).clamp(0.0, 1.0);
                Vec3::splat(0.04).lerp(Vec3::ONE, a)
            }
            ShadingMode::Unlit => {
                if s.material.native == Native::Pbr {
                    let c = self.pbr_color_at(s);
                    Vec3::from(c.base) + Vec3::from(c.emissive)
                } else {
                    let c = self.surface_color(s.material, &mut fetch, f.color);
                    Vec3::from(c.kd) + Vec3::from(c.ke)
                }
            }
            ShadingMode::Gouraud => {
                let (d, sp) = s.vertex_light.unwrap_or((Vec3::ZERO, Vec3::ZERO));
                let sums = Some((V3::from(d), V3::from(sp)));
                self.shade_blinn_phong(s.material, &mut fetch, &f, sums)
                    .into()
            }
            ShadingMode::Auto if s.material.native == Native::Pbr => {
                self.shade_pbr(s.material, &mut fetch, &f).into()
            }
            ShadingMode::Pbr => self.shade_pbr(s.material, &mut fetch, &f).into(),
            // Flat: the triangle's normal (already in `s.normal`).
            ShadingMode::BlinnPhong | ShadingMode::Auto | ShadingMode::Flat => self
                .shade_blinn_phong(s.material, &mut fetch, &f, None)
                .into(),
        }
    }

    /// The data passes' values of a surface point: its shading normal
    /// (normal and bump maps applied; the triangle's in flat mode), world
    /// space, unit, facing the camera; and its base colour after textures,
    /// linear (glTF's base colour, or Kd), times the vertex colour.
    pub fn aov(&self, s: &Surface) -> (Vec3, Vec3) {
        let normal = if self.mode == ShadingMode::Flat {
            s.normal
        } else {
            self.mapped_normal(s)
        };
        let pbr = match self.mode {
            ShadingMode::Pbr => true,
            ShadingMode::BlinnPhong | ShadingMode::Flat | ShadingMode::Gouraud => false,
            _ => s.material.native == Native::Pbr,
        };
        let albedo = if pbr {
            self.pbr_color_at(s).base
        } else {
            let f = Lanes::of(s);
            self.surface_color(s.material, &mut One { ctx: self, s }, f.color)
                .kd
        };
        (normal.normalize_or(Vec3::Z), albedo.into())
    }

    /// The material's metallic-roughness factors times its maps at a
    /// surface point.
    pub fn pbr_color_at(&self, s: &Surface) -> PbrColor {
        self.pbr_color(s.material, &mut One { ctx: self, s }, &Lanes::of(s))
    }

    /// Whether a point of `m` is shaded with metallic-roughness.
    fn shades_pbr(&self, m: &Material) -> bool {
        match self.mode {
            ShadingMode::Pbr => true,
            ShadingMode::Auto => m.native == Native::Pbr && !m.unlit,
            _ => false,
        }
    }

    /// A blended surface as a layer over what lies behind it: the light
    /// it adds, the fraction of the light behind that it lets through (per
    /// channel) and its coverage for the alpha channel. Opacity (d, maps,
    /// base alpha) gives (c a, 1 - a, a); transmission (pbr) gives the
    /// reflected light, its transmittance and 1 - their mean.
    pub fn layer(&self, s: &Surface) -> (Vec3, Vec3, f32) {
        let c = self.shade(s);
        if s.material.pbr.transmission.is_some() && self.shades_pbr(s.material) {
            let pc = self.pbr_color_at(s);
            let n = self.mapped_normal(s);
            let t = pc.transmittance(n, self.view_vector(s.position));
            let t = t.clamp(Vec3::ZERO, Vec3::ONE);
            return (c, t, 1.0 - (t.x + t.y + t.z) / 3.0);
        }
        let a = self.opacity(s.material, &s.tc, s.color).clamp(0.0, 1.0);
        (c * a, Vec3::splat(1.0 - a), a)
    }

    /// A filtered lookup of `t` at the point's coordinates in its set (None
    /// where the mesh has no such set).
    #[inline]
    fn sample(&self, t: &TextureRef, tc: &TexCoords) -> Option<Vec4> {
        let set = (t.texcoord as usize).min(1);
        let uv = tc.uv[set]?;
        let f = Filtering {
            filter: self.filter,
            max_anisotropy: self.max_anisotropy,
            mips: self.mips.get(t.texture.id).copied().flatten(),
        };
        if f.mips.is_some()
            && matches!(f.filter, Filter::Trilinear | Filter::Anisotropic)
            && t.is_plain()
        {
            let tex = &t.texture;
            let key = (tex.width, tex.height);
            let fp = match tc.footprint[set].get() {
                Some((k, fp)) if k == key => fp,
                _ => {
                    let fp = tex.footprint(tc.grads[set], &f);
                    tc.footprint[set].set(Some((key, fp)));
                    fp
                }
            };
            let mode = t.address.unwrap_or(self.address.into());
            return Some(tex.chain(f.mips).sample1(uv, fp, mode));
        }
        Some(t.sample_grad(uv, tc.grads[set], self.address, f))
    }

    /// Opacity at the point: d (glTF: the base color's alpha) times map_d
    /// (its alpha, or red without alpha) times the alpha of map_kd (glTF:
    /// of the base color texture) times the vertex color's alpha.
    pub fn opacity(&self, m: &Material, tc: &TexCoords, color: Vec4) -> f32 {
        let rgba = |t: &TextureRef| self.sample(t, tc).map(|c| (V3::from(c.truncate()), c.w));
        self.opacity_of(m, rgba, color.w)
    }

    /// `opacity` at the lanes' points, whose vertex colours have alpha
    /// `alpha`, reading maps through `rgba` (`Fetch::rgba`).
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

    /// The shading normal with the material's normal or bump map applied.
    pub fn mapped_normal(&self, s: &Surface) -> Vec3 {
        match &s.material.normal_map {
            Some(map) => self.apply_normal_map(s, map),
            None => s.normal,
        }
    }

    /// The interpolated normal perturbed by `map`.
    fn apply_normal_map(&self, s: &Surface, map: &NormalMap) -> Vec3 {
        let tc = &s.tc;
        let n = s.normal;
        let frame = |t: Vec4| {
            let tt = (t.truncate() - n * n.dot(t.truncate()))
                .try_normalize()
                .unwrap_or_else(|| n.any_orthonormal_vector());
            let b = n.cross(tt) * if t.w < 0.0 { -1.0 } else { 1.0 };
            (tt, b)
        };
        let mapped = match map {
            NormalMap::Normals {
                map,
                space: NormalSpace::Tangent,
                scale,
            } => {
                let Some(c) = self.sample(map, tc) else {
                    return n;
                };
                let Some(t) = s.tangent else { return n };
                // The lanes' code at one lane (already unit).
                let t = (V3::from(t.truncate()), t.w);
                return lanes::tangent_space(V3::from(n), t, V3::from(c.truncate()), *scale).into();
            }
            NormalMap::Normals {
                map,
                space: NormalSpace::Object,
                ..
            } => {
                let Some(c) = self.sample(map, tc) else {
                    return n;
                };
                // The lanes' code at one lane (already unit). Back faces
                // are lit on their flipped side.
                let back = s.normal.dot(s.raw_normal) < 0.0;
                let c = V3::from(c.truncate());
                return lanes::object_space(V3::from(n), back, s.normal_from_object, c).into();
            }
            NormalMap::Height { map, scale } => {
                let Some(t) = s.tangent else { return n };
                let set = (map.texcoord as usize).min(1);
                let Some(uv) = tc.uv[set] else { return n };
                let g = tc.grads[set];
                let (tt, b) = frame(t);
                let tex = &map.texture;
                let m2 = map.transform.matrix2;
                let size = Vec2::new(tex.width as f32, tex.height as f32)
                    * Vec2::new(m2.x_axis.length(), m2.y_axis.length());
                // Central differences across one pixel footprint (at least
                // one texel), each sample filtered at the footprint's level.
                let texels = (g.dx * size).length().max((g.dy * size).length());
                let step = texels.max(1.0) / size;
                let h = |d: Vec2| {
                    let mut at = tc.clone();
                    at.uv[set] = Some(uv + d);
                    self.sample(map, &at).map_or(0.0, |c| c.x)
                };
                let du = (h(Vec2::new(step.x, 0.0)) - h(Vec2::new(-step.x, 0.0))) * 0.5;
                // Image rows run down; the bitangent points up the image.
                let dv = (h(Vec2::new(0.0, -step.y)) - h(Vec2::new(0.0, step.y))) * 0.5;
                n - tt * (du * scale) - b * (dv * scale)
            }
        };
        mapped.try_normalize().unwrap_or(n)
    }
}

/// Where shading code (written once over the lane type `L`) reads a
/// material's texels and perturbs its normals: one fragment's through
/// `ShadeContext::sample` (`One`), a lane call's through its prepared
/// maps (`shade::lanes`).
pub(crate) trait Fetch<L: Lane> {
    /// Red, green, blue and alpha of `t` at the lanes' points; None where
    /// the mesh has no coordinates of its set (the map then counts as 1).
    fn rgba(&mut self, t: &TextureRef) -> Option<(V3<L>, L)>;

    /// The lanes' interpolated normals perturbed by `map`, unit.
    fn normal(&mut self, map: &NormalMap) -> V3<L>;

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

/// One fragment's texels: every kind of map, filtered as the frame asks.
struct One<'c, 's> {
    ctx: &'c ShadeContext<'c>,
    s: &'s Surface<'s>,
}

impl Fetch<f32> for One<'_, '_> {
    #[inline]
    fn rgba(&mut self, t: &TextureRef) -> Option<(V3<f32>, f32)> {
        let c = self.ctx.sample(t, &self.s.tc)?;
        Some((V3::from(c.truncate()), c.w))
    }

    #[inline]
    fn normal(&mut self, map: &NormalMap) -> V3<f32> {
        // Flat shading keeps the triangle's normal.
        if self.ctx.mode == ShadingMode::Flat {
            return V3::from(self.s.normal);
        }
        V3::from(self.ctx.apply_normal_map(self.s, map))
    }
}

impl Lanes<f32> {
    /// A surface point as the one-lane instance of the shading code
    /// takes it.
    #[inline]
    pub fn of(s: &Surface) -> Lanes<f32> {
        Lanes {
            position: V3::from(s.position),
            normal: V3::from(s.normal),
            color: Some(V3::from(s.color.truncate())),
            geo_normal: [s.geo_normal; lanes::MAX_LANES],
            ao: s.ao,
            depth: s.view_depth,
            edge: s.edge_distance,
            lights: s.lights,
            vertex_light: s.vertex_light.map(|(d, s)| (V3::from(d), V3::from(s))),
        }
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
            address: AddressMode::Repeat,
            mips: &[],
            depth_range: (0.0, 1.0),
            shadows,
            env: None,
            env_sampled: None,
            pixel_scale: 1.0,
        }
    }
}
