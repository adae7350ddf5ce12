//! The surface of a triangle at a fragment: where a fragment is
//! interpolated (the pixel center or the covered samples' centroid), its
//! position and normals (`point`: the geometry buffer, the data passes'
//! depth), texture coordinates in both sets (`material_uv`: the alpha
//! test) with their quad derivatives (`gradients`: the footprints the
//! lanes filter over), and the wireframe's edge distance.

use glam::{Vec2, Vec3, Vec4};

use super::fragment::{BandInputs, Point};
use crate::assets::texture::Gradients;
use crate::raster::interp::{Fragment, Interpolator};
use crate::raster::setup::Tri;
use crate::scene::settings::ShadingMode;
use crate::shade::lanes::LaneMaterial;
use crate::shade::light::LightMask;

impl<'a> BandInputs<'a> {
    /// Where a fragment of `it` covering samples `mask` of pixel (px, py)
    /// is interpolated: the pixel center when it is inside the triangle,
    /// otherwise the centroid of the covered samples.
    #[inline]
    pub(super) fn shading_point(&self, it: &Interpolator, px: i32, py: i32, mask: u32) -> Fragment {
        if self.pattern.len() == 1 || it.covers_center(px, py) {
            return it.at_pixel(px, py);
        }
        self.centroid_point(it, px, py, mask)
    }

    /// `shading_point` where the triangle does not cover the pixel's
    /// center (with MSAA): the covered samples' centroid.
    pub(super) fn centroid_point(
        &self,
        it: &Interpolator,
        px: i32,
        py: i32,
        mask: u32,
    ) -> Fragment {
        let (mut sx, mut sy, mut k) = (0i32, 0i32, 0i32);
        for (s, &(ox, oy)) in self.pattern.iter().enumerate() {
            if mask & (1 << s) != 0 {
                sx += ox as i32;
                sy += oy as i32;
                k += 1;
            }
        }
        let k = (16 * k.max(1)) as f64;
        it.at(
            px as f64 + 0.5 + sx as f64 / k,
            py as f64 + 0.5 + sy as f64 / k,
        )
    }

    /// The material of `t`, its texture coordinates (both sets) and vertex
    /// color at barycentrics `l`.
    pub(super) fn material_uv(
        &self,
        t: &Tri,
        l: Vec3,
    ) -> (&crate::scene::Material, [Option<Vec2>; 2], Vec4) {
        let d = self.draws[t.draw as usize];
        let model = &self.setup.scene.models[d.model];
        let mesh = &model.mesh;
        let idx = mesh.triangles[t.prim as usize].map(|i| i as usize);
        let at = |uv: &[Vec2]| {
            (!uv.is_empty()).then(|| uv[idx[0]] * l.x + uv[idx[1]] * l.y + uv[idx[2]] * l.z)
        };
        let color = if mesh.colors.is_empty() {
            Vec4::ONE
        } else {
            let c = &mesh.colors;
            c[idx[0]] * l.x + c[idx[1]] * l.y + c[idx[2]] * l.z
        };
        (
            &model.materials[d.material],
            [at(&mesh.uvs), at(&mesh.uvs1)],
            color,
        )
    }

    /// Texture-coordinate derivatives of `t` (both sets) over a quad,
    /// from its top-left, top-right and bottom-left centres `centers`
    /// (`quad_centers`).
    fn gradients_at(&self, t: &Tri, centers: &[Fragment]) -> [Gradients; 2] {
        let uv = |k: usize| self.material_uv(t, centers[k].lambda).1;
        let (a, b, c) = (uv(0), uv(1), uv(2));
        [0, 1].map(|k| match (a[k], b[k], c[k]) {
            (Some(a), Some(b), Some(c)) => Gradients {
                dx: b - a,
                dy: c - a,
            },
            _ => Gradients::default(),
        })
    }

    /// The texture derivatives the footprints of lane material `lm`
    /// need over the quad at `q0`: none where filtering does not read
    /// them, set 0 alone unless some map reads set 1.
    pub(super) fn lane_gradients(
        &self,
        lm: &LaneMaterial,
        t: &Tri,
        it: &Interpolator,
        q0: (i32, i32),
    ) -> [Gradients; 2] {
        if !self.grads {
            [Gradients::default(); 2]
        } else {
            self.lane_gradients_at(lm, t, &quad_centers(it, q0))
        }
    }

    /// `lane_gradients` where they are wanted (`self.grads`), from the
    /// quad's `quad_centers` (the first three of `centers`).
    pub(super) fn lane_gradients_at(
        &self,
        lm: &LaneMaterial,
        t: &Tri,
        centers: &[Fragment],
    ) -> [Gradients; 2] {
        if lm.reads_set1() {
            self.gradients_at(t, centers)
        } else {
            [self.gradients0_at(t, centers), Gradients::default()]
        }
    }

    /// Whether fragments need their texture-coordinate derivatives.
    #[inline(always)]
    pub(super) fn wants_gradients(&self) -> bool {
        self.grads
    }

    /// `gradients_at` of set 0 alone.
    fn gradients0_at(&self, t: &Tri, centers: &[Fragment]) -> Gradients {
        let d = self.draws[t.draw as usize];
        let mesh = &self.setup.scene.models[d.model].mesh;
        let uv = &mesh.uvs;
        if uv.is_empty() {
            return Gradients::default();
        }
        let idx = mesh.triangles[t.prim as usize].map(|i| i as usize);
        let at = |k: usize| {
            let l = centers[k].lambda;
            uv[idx[0]] * l.x + uv[idx[1]] * l.y + uv[idx[2]] * l.z
        };
        let (a, b, c) = (at(0), at(1), at(2));
        Gradients {
            dx: b - a,
            dy: c - a,
        }
    }

    /// Position, normals and view depth of triangle `t` at a fragment.
    #[inline]
    pub(super) fn point(&self, t: &Tri, frag: Fragment) -> Point {
        let ctx = &self.ctx;
        let d = self.draws[t.draw as usize];
        let model = &self.setup.scene.models[d.model];
        let mv = &self.verts[d.model];
        let idx = model.mesh.triangles[t.prim as usize].map(|v| v as usize);
        let l = frag.lambda;
        let lerp3 = |a: &[Vec3]| a[idx[0]] * l.x + a[idx[1]] * l.y + a[idx[2]] * l.z;
        let position = lerp3(&mv.world);
        let raw_normal = lerp3(&mv.normal);
        let view_depth = if ctx.orthographic {
            (position - ctx.eye).dot(ctx.forward)
        } else {
            frag.w
        };
        // Light the side the camera sees.
        let n = raw_normal.normalize_or(Vec3::Y);
        let normal = if t.front { n } else { -n };
        let geo_normal = if self.geo_normal {
            let [a, b, c] = idx.map(|k| mv.world[k]);
            let g = (b - a).cross(c - a).normalize_or(normal);
            if g.dot(ctx.view_vector(position)) < 0.0 {
                -g
            } else {
                g
            }
        } else {
            normal
        };
        Point {
            position,
            normal,
            geo_normal,
            view_depth,
        }
    }
}

/// What reaches a fragment besides its triangle: its ambient occlusion
/// (1: none) and the lights that may reach its tile.
#[derive(Debug, Clone, Copy)]
pub(super) struct FragmentLighting {
    pub ao: f32,
    pub lights: LightMask,
}

impl BandInputs<'_> {
    /// Wireframe shading: the distance in pixels from the shading point
    /// (barycentrics `l`) in pixel (px, py) to the nearest edge of the
    /// triangle `it` interpolates; infinite in the other modes.
    #[inline]
    pub(super) fn edge_distance(&self, it: &Interpolator, px: i32, py: i32, l: Vec3) -> f32 {
        if self.ctx.mode == ShadingMode::Wireframe {
            edge_distance(it, px, py, l)
        } else {
            f32::INFINITY
        }
    }
}

/// Screen-space distance (pixels) from the pixel center to the nearest edge
/// of the original triangle: each barycentric over the length of its
/// screen-space gradient.
fn edge_distance(it: &Interpolator, px: i32, py: i32, l: Vec3) -> f32 {
    // Gradients per pixel step; `l` may be off the center (MSAA centroid).
    let c = it.at_pixel(px, py).lambda;
    let dx = it.at_pixel(px + 1, py).lambda - c;
    let dy = it.at_pixel(px, py + 1).lambda - c;
    let mut best = f32::INFINITY;
    for k in 0..3 {
        let g = Vec2::new(dx[k], dy[k]).length();
        if g > 0.0 {
            best = best.min(l[k] / g);
        }
    }
    best
}

/// The centres of the quad whose top-left pixel is `q0` that texture
/// derivatives are taken between: its top-left, top-right and
/// bottom-left pixels' (`Interpolator::at_pixel`).
#[inline]
pub(super) fn quad_centers(it: &Interpolator, q0: (i32, i32)) -> [Fragment; 3] {
    [
        it.at_pixel(q0.0, q0.1),
        it.at_pixel(q0.0 + 1, q0.1),
        it.at_pixel(q0.0, q0.1 + 1),
    ]
}
