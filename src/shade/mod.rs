//! Shading: what color a visible surface point gets, per `render.shading`.
//! Shading reads the scene (materials, lights) and never writes to it.

pub mod blinn_phong;
pub mod tonemap;

use glam::{Mat3, Vec2, Vec3, Vec4};

use crate::assets::texture::{Filtering, Gradients, TextureRef};
use crate::scene::desc::{AddressMode, ShadingMode, TextureFilter};
use crate::scene::material::{NormalMap, NormalSpace};
use crate::scene::{Light, Material};
use blinn_phong::SurfaceColor;

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
    /// Per texture id: whether this frame may read its mip chain (it
    /// minifies the texture somewhere, and the chain is built).
    pub mips: &'a [bool],
    /// View-depth range mapped to white..black by the `depth` view.
    pub depth_range: (f32, f32),
}

/// A visible point, interpolated.
pub struct Surface<'a> {
    pub material: &'a Material,
    pub position: Vec3,
    /// Unit shading normal, facing the side the camera sees.
    pub normal: Vec3,
    /// Interpolated vertex normal as stored (for the `normals` view).
    pub raw_normal: Vec3,
    pub uv: Option<Vec2>,
    /// Texture-coordinate derivatives along screen x and y.
    pub grads: Gradients,
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
        match self.mode {
            // The shading normal (normal and bump maps applied), world space.
            ShadingMode::Normals => self.mapped_normal(s) * 0.5 + Vec3::splat(0.5),
            ShadingMode::Depth => {
                let (lo, hi) = self.depth_range;
                Vec3::splat(1.0 - ((s.view_depth - lo) / (hi - lo)).clamp(0.0, 1.0))
            }
            ShadingMode::Wireframe => {
                // A one-pixel line with a one-pixel soft edge, white on the fill.
                let a = (1.5 - s.edge_distance).clamp(0.0, 1.0);
                Vec3::splat(0.04).lerp(Vec3::ONE, a)
            }
            ShadingMode::Unlit => {
                let c = self.surface_color(s.material, s.uv, s.grads);
                c.kd + c.ke
            }
            ShadingMode::Gouraud => {
                let c = self.surface_color(s.material, s.uv, s.grads);
                let (d, sp) = s.vertex_light.unwrap_or((Vec3::ZERO, Vec3::ZERO));
                blinn_phong::combine(&c, self.ambient, d, sp)
            }
            ShadingMode::BlinnPhong => {
                let c = self.surface_color(s.material, s.uv, s.grads);
                let v = self.view_vector(s.position);
                let n = self.mapped_normal(s);
                blinn_phong::radiance(s.position, n, v, &c, self.ambient, self.lights)
            }
            ShadingMode::Flat => {
                let c = self.surface_color(s.material, s.uv, s.grads);
                let v = self.view_vector(s.position);
                blinn_phong::radiance(s.position, s.normal, v, &c, self.ambient, self.lights)
            }
        }
    }

    /// A filtered lookup of `t` at the surface's coordinates.
    #[inline]
    fn sample(&self, t: &TextureRef, uv: Vec2, g: Gradients) -> Vec4 {
        let f = Filtering {
            filter: self.filter,
            max_anisotropy: self.max_anisotropy,
            mips: self.mips.get(t.texture.id).copied().unwrap_or(false),
        };
        t.sample_grad(uv, g, self.address, f)
    }

    /// The material's constants times its texture maps at `uv`.
    #[inline]
    pub fn surface_color(&self, m: &Material, uv: Option<Vec2>, g: Gradients) -> SurfaceColor {
        let sample = |t: &Option<TextureRef>| -> Vec3 {
            match (t, uv) {
                (Some(t), Some(uv)) => self.sample(t, uv, g).truncate(),
                _ => Vec3::ONE,
            }
        };
        let kd = m.kd * sample(&m.map_kd);
        let ka = match m.ka {
            Some(ka) => ka * sample(&m.map_ka),
            None => kd,
        };
        let ns = match (&m.map_ns, uv) {
            (Some(t), Some(uv)) => m.ns * self.sample(t, uv, g).x,
            _ => m.ns,
        };
        SurfaceColor {
            ka,
            kd,
            ks: if m.illum >= 2 {
                m.ks * sample(&m.map_ks)
            } else {
                Vec3::ZERO
            },
            ke: if m.ke == Vec3::ZERO {
                Vec3::ZERO
            } else {
                m.ke * sample(&m.map_ke)
            },
            ns,
            illum: m.illum,
        }
    }

    /// Opacity at the point: d times map_d (its alpha, or red without
    /// alpha) times the alpha of map_Kd.
    pub fn opacity(&self, m: &Material, uv: Option<Vec2>, g: Gradients) -> f32 {
        let mut a = m.d;
        if let Some(uv) = uv {
            if let Some(t) = &m.map_d {
                let c = self.sample(t, uv, g);
                a *= if t.texture.has_alpha { c.w } else { c.x };
            }
            if let Some(t) = &m.map_kd
                && t.texture.has_alpha
            {
                a *= self.sample(t, uv, g).w;
            }
        }
        a
    }

    /// The shading normal with the material's normal or bump map applied.
    pub fn mapped_normal(&self, s: &Surface) -> Vec3 {
        let (Some(map), Some(uv)) = (&s.material.normal_map, s.uv) else {
            return s.normal;
        };
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
                let c = self.sample(map, uv, s.grads).truncate() * 2.0 - Vec3::ONE;
                let Some(t) = s.tangent else { return n };
                let (tt, b) = frame(t);
                tt * (c.x * scale) + b * (c.y * scale) + n * c.z
            }
            NormalMap::Normals {
                map,
                space: NormalSpace::Object,
                ..
            } => {
                let c = self.sample(map, uv, s.grads).truncate() * 2.0 - Vec3::ONE;
                let w = s.normal_from_object * c;
                // Back faces are lit on their flipped side.
                if s.normal.dot(s.raw_normal) < 0.0 {
                    -w
                } else {
                    w
                }
            }
            NormalMap::Height { map, scale } => {
                let Some(t) = s.tangent else { return n };
                let (tt, b) = frame(t);
                let tex = &map.texture;
                let size = Vec2::new(tex.width as f32, tex.height as f32) * map.scale;
                // Central differences across one pixel footprint (at least
                // one texel), each sample filtered at the footprint's level.
                let texels = (s.grads.dx * size)
                    .length()
                    .max((s.grads.dy * size).length());
                let step = texels.max(1.0) / size;
                let h = |d: Vec2| self.sample(map, uv + d, s.grads).x;
                let du = (h(Vec2::new(step.x, 0.0)) - h(Vec2::new(-step.x, 0.0))) * 0.5;
                // Image rows run down; the bitangent points up the image.
                let dv = (h(Vec2::new(0.0, -step.y)) - h(Vec2::new(0.0, step.y))) * 0.5;
                n - tt * (du * scale) - b * (dv * scale)
            }
        };
        mapped.try_normalize().unwrap_or(n)
    }
}

/// Background pixel: linear color with alpha (0 for transparent).
pub fn background(bg: crate::scene::desc::Background) -> Vec4 {
    match bg {
        crate::scene::desc::Background::Color(c) => Vec3::from(c).extend(1.0),
        crate::scene::desc::Background::Transparent => Vec4::ZERO,
    }
}
