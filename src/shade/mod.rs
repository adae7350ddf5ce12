//! Shading: what color a visible surface point gets, per `render.shading`.
//! Shading reads the scene (materials, lights) and never writes to it.

pub mod blinn_phong;
pub mod tonemap;

use glam::{Vec2, Vec3, Vec4};

use crate::scene::desc::{AddressMode, ShadingMode, TextureFilter};
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
    pub address: AddressMode,
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
            ShadingMode::Normals => s.raw_normal * 0.5 + Vec3::splat(0.5),
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
                let c = self.surface_color(s.material, s.uv);
                c.kd + c.ke
            }
            ShadingMode::Gouraud => {
                let c = self.surface_color(s.material, s.uv);
                let (d, sp) = s.vertex_light.unwrap_or((Vec3::ZERO, Vec3::ZERO));
                blinn_phong::combine(&c, self.ambient, d, sp)
            }
            ShadingMode::BlinnPhong | ShadingMode::Flat => {
                let c = self.surface_color(s.material, s.uv);
                let v = self.view_vector(s.position);
                blinn_phong::radiance(s.position, s.normal, v, &c, self.ambient, self.lights)
            }
        }
    }

    /// The material's constants times its texture maps at `uv`.
    #[inline]
    pub fn surface_color(&self, m: &Material, uv: Option<Vec2>) -> SurfaceColor {
        let nearest = self.filter == TextureFilter::Nearest;
        let sample = |t: &Option<crate::assets::texture::TextureRef>| -> Vec3 {
            match (t, uv) {
                (Some(t), Some(uv)) => t.sample(uv, self.address, nearest).truncate(),
                _ => Vec3::ONE,
            }
        };
        let kd = m.kd * sample(&m.map_kd);
        let ka = match m.ka {
            Some(ka) => ka * sample(&m.map_ka),
            None => kd,
        };
        SurfaceColor {
            ka,
            kd,
            ks: m.ks * sample(&m.map_ks),
            ke: if m.ke == Vec3::ZERO {
                Vec3::ZERO
            } else {
                m.ke * sample(&m.map_ke)
            },
            ns: m.ns,
            illum: m.illum,
        }
    }
}

/// Background pixel: linear color with alpha (0 for transparent).
pub fn background(bg: crate::scene::desc::Background) -> Vec4 {
    match bg {
        crate::scene::desc::Background::Color(c) => Vec3::from(c).extend(1.0),
        crate::scene::desc::Background::Transparent => Vec4::ZERO,
    }
}
