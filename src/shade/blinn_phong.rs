//! Blinn-Phong exactly as the scene format states it:
//!
//!   L = Ke + Ka * ambient + sum_lights E * max(0, n.l) * (Kd + Ks * max(0, n.h)^Ns)
//!
//! with `illum 0`: L = Kd; `illum 1`: no specular term; `illum 2` and up: all
//! terms. All quantities are linear RGB; textures already multiplied in.
//! The environment adds Kd E(n) / pi (times AO; under `bounces = 1`, E with
//! the light bounced off the surfaces around, without AO) plus Ks times the
//! radiance prefiltered along the reflection with the GGX lobe that matches
//! Ns.
//!
//! Written once over the lane type (`shade::lanes`); Gouraud shading sums
//! the lights at the vertices with the same code and combines the sums per
//! pixel.

use std::f32::consts::PI;

use glam::Vec3;

use super::env::dominant_direction_lanes;
use super::env::reflect::At;
use super::env::sampled::{self as env_sampled, Lobes};
use super::lanes::{Lanes, Lit};
use super::{Fetch, ShadeContext};
use crate::scene::Material;
use crate::scene::light::{Light, LightKind};
use crate::scene::material::roughness_from_ns;
use crate::simd::{Lane, Mask, V3};

/// A material evaluated at the lanes' points (constants times texture
/// lookups).
#[derive(Debug, Clone, Copy)]
pub struct SurfaceColor<L: Lane = f32> {
    pub ka: V3<L>,
    pub kd: V3<L>,
    pub ks: V3<L>,
    pub ke: V3<L>,
    pub ns: L,
    pub illum: u8,
}

/// `factor` times texels, where there are any.
#[inline(always)]
fn times<L: Lane>(factor: Vec3, texel: Option<V3<L>>) -> V3<L> {
    match texel {
        Some(c) => V3::splat(factor) * c,
        None => V3::splat(factor),
    }
}

impl ShadeContext<'_> {
    /// The material's constants times its texture maps (and the vertex
    /// colours `color`) at the lanes' points.
    #[inline(always)]
    pub(crate) fn surface_color<L: Lane>(
        &self,
        m: &Material,
        fetch: &mut impl Fetch<L>,
        color: Option<V3<L>>,
    ) -> SurfaceColor<L> {
        let mut kd = times(m.kd, fetch.rgb_of(&m.map_kd));
        if let Some(c) = color {
            kd = kd * c;
        }
        SurfaceColor {
            ka: match m.ka {
                Some(ka) => times(ka, fetch.rgb_of(&m.map_ka)),
                None => kd,
            },
            kd,
            ks: if m.illum >= 2 {
                times(m.ks, fetch.rgb_of(&m.map_ks))
            } else {
                V3::zero()
            },
            ke: if m.ke == Vec3::ZERO {
                V3::zero()
            } else {
                times(m.ke, fetch.rgb_of(&m.map_ke))
            },
            ns: match fetch.rgb_of(&m.map_ns) {
                Some(c) => L::splat(m.ns) * c.x,
                None => L::splat(m.ns),
            },
            illum: m.illum,
        }
    }

    /// Blinn-Phong shading of material `m` at the lanes' points; with
    /// `vertex_light` (Gouraud), the interpolated (diffuse, specular)
    /// light sums replace the lights, about the interpolated normal.
    #[inline(always)]
    pub(crate) fn shade_blinn_phong<L: Lane>(
        &self,
        m: &Material,
        fetch: &mut impl Fetch<L>,
        f: &Lanes<L>,
        vertex_light: Option<(V3<L>, V3<L>)>,
    ) -> V3<L> {
        let c = self.surface_color(m, fetch, f.color);
        // illum 0 is the colour alone, without any light.
        if c.illum == 0 {
            return c.kd;
        }
        let v = self.view_lanes(f.position);
        let specular = c.illum >= 2;
        let (n, (diffuse, spec)) = match vertex_light {
            Some(sums) => (f.normal, sums),
            None => {
                let n = match &m.normal_map {
                    Some(map) => fetch.normal(map),
                    None => f.normal,
                };
                (n, self.light_sums(f, [n, v], c.ns, specular))
            }
        };
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let spec_term = if specular { c.ks * spec } else { V3::zero() };
        let out = c.ke + c.ka * ambient + c.kd * diffuse + spec_term;
        match self.env {
            Some(_) => out + self.env_blinn_phong(f, [n, v], &c),
            None => out,
        }
    }

    /// Sum over the lights of E max(0, n.l) (diffuse) and, for a
    /// `specular` material, E max(0, n.l) max(0, n.h)^ns, at the points
    /// with unit normals `n` seen from `v`.
    #[inline(always)]
    pub(crate) fn light_sums<L: Lane>(
        &self,
        f: &Lanes<L>,
        [n, v]: [V3<L>; 2],
        ns: L,
        specular: bool,
    ) -> (V3<L>, V3<L>) {
        let zero = L::splat(0.0);
        let mut diffuse = V3::zero();
        let mut spec = V3::zero();
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, e, lit, .. } = self.lit_lanes(i, light, f, n);
            if let Some(w2) = disc(light, f.position) {
                // Taken out of the environment, or an emissive surface:
                // lit as the environment lit these surfaces.
                let (d, s) = image_light([n, v, l], e, ns, w2);
                diffuse = diffuse + V3::select(lit, d, V3::zero());
                if specular {
                    spec = spec + V3::select(lit, s, V3::zero());
                }
                return;
            }
            diffuse = diffuse + V3::select(lit, e, V3::zero());
            if specular {
                let h = (l + v).normalize_or(V3::zero());
                let ndh = n.dot(h).max(zero);
                let shine = lit & ndh.cmpgt(zero);
                if shine.any() {
                    // Lanes that do not shine give what they give (x = 0:
                    // 2^-126 raised), left out by the select.
                    let pw = crate::powers::pow(ndh, ns);
                    spec = spec + V3::select(shine, e.scale(pw), V3::zero());
                }
            }
        });
        (diffuse, spec)
    }

    /// The environment's light on the points (normals and view vectors
    /// `[n, v]`): Kd E(n) / pi (times AO) plus Ks times the radiance
    /// prefiltered along the reflection with the GGX lobe that matches
    /// Ns, or the sampled environment's estimate of both.
    fn env_blinn_phong<L: Lane>(
        &self,
        f: &Lanes<L>,
        [n, v]: [V3<L>; 2],
        c: &SurfaceColor<L>,
    ) -> V3<L> {
        let Some(env) = self.env else {
            return V3::zero();
        };
        let zero = L::splat(0.0);
        let roughness = c.ns.map(roughness_from_ns);
        if let Some(sampled) = &self.env_sampled {
            return V3::from_fn(|k| {
                let lobes = Lobes::BlinnPhong {
                    kd: c.kd.lane(k),
                    ks: c.ks.lane(k),
                    roughness: roughness.lane(k),
                };
                let point = (f.position.lane(k), &[n.lane(k)][..], f.geo_normal[k]);
                env_sampled::radiance(sampled, point, v.lane(k), &lobes)
            });
        }
        // Under `bounces = 1` the diffuse light gathers the surfaces
        // around, as a pbr material's does; its rays see what hides the
        // environment, so the AO does not darken that light again.
        let gathered = self.env_reflections.as_ref().filter(|r| r.bounce);
        let diffuse = match gathered {
            Some(with) => {
                let at = At {
                    with,
                    position: f.position,
                    geo_normal: &f.geo_normal[..],
                };
                (c.kd * at.irradiance(env.irradiance_lanes(n), n)).scale(L::splat(1.0 / PI))
            }
            None => (c.kd * env.irradiance_lanes(n)).scale(f.ao / L::splat(PI)),
        };
        let ks = c.ks;
        let no_ks = ks.x.cmpeq(zero) & ks.y.cmpeq(zero) & ks.z.cmpeq(zero);
        if no_ks.all() {
            return diffuse;
        }
        let r = n.scale(L::splat(2.0) * n.dot(v)) - v;
        let r = dominant_direction_lanes(n, r, roughness);
        let r0 = roughness.lane(0);
        let light = if roughness.cmpeq(L::splat(r0)).all() {
            env.prefiltered_phong_lanes(r, r0)
        } else {
            V3::from_fn(|k| env.prefiltered_phong(r.lane(k), roughness.lane(k)))
        };
        V3::select(no_ks, diffuse, diffuse + ks * light)
    }
}

/// For a light with a disc, (tan(angle) / 2)^2 of the disc's angular
/// radius as the points `p` see it: a light taken out of the image
/// (`environment.lights`) or an emissive surface (`environment.emitters`,
/// tan = radius / distance). None for the others.
#[inline(always)]
fn disc<L: Lane>(light: &Light, p: V3<L>) -> Option<L> {
    match light.kind {
        LightKind::Directional { angle, .. } if angle > 0.0 => {
            let w = 0.5 * angle.tan();
            Some(L::splat(w * w))
        }
        LightKind::Area {
            position, radius, ..
        } => {
            let d = V3::splat(position) - p;
            let w = L::splat(0.5 * radius) / d.dot(d).sqrt();
            Some(w * w)
        }
        _ => None,
    }
}

/// A light with a disc (`disc`: w2 = (tan(angle) / 2)^2 of its angular
/// radius) as the environment term shaded it:
/// (E n.l / pi, E n.l D(r.h) / 4), with which Kd and Ks make Kd E(n) / pi
/// and Ks times the radiance along the reflection r weighted by the GGX
/// lobe matching Ns (D over the reflected directions, around r, is a
/// distribution: D(r.h) / 4 is its density at l; alpha^2 = 2 / (Ns + 2),
/// widened by the disc as `PbrColor::widened` does).
#[inline(always)]
fn image_light<L: Lane>([n, v, l]: [V3<L>; 3], e: V3<L>, ns: L, w2: L) -> (V3<L>, V3<L>) {
    let one = L::splat(1.0);
    let a2 = (L::splat(2.0) / (ns.max(L::splat(0.0)) + L::splat(2.0)) + w2).min(one);
    let r = n.scale(L::splat(2.0) * n.dot(v)) - v;
    let h = (l + r).normalize_or(V3::zero());
    let c = r.dot(h).max(L::splat(0.0));
    let q = c * c * (a2 - one) + one;
    let d = a2 / (L::splat(PI) * q * q);
    (e.scale(L::splat(1.0 / PI)), e.scale(d * L::splat(0.25)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light::{Light, LightKind};
    use crate::shade::light::LightMask;
    use crate::shade::shadow::Shadows;
    use crate::shade::testing::context;

    /// No texture maps.
    struct Plain;

    impl Fetch<f32> for Plain {
        fn rgba(&mut self, _: &crate::assets::texture::TextureRef) -> Option<(V3<f32>, f32)> {
            None
        }

        fn normal(&mut self, _: &crate::scene::material::NormalMap) -> V3<f32> {
            V3::from(Vec3::Y)
        }
    }

    fn material(illum: u8) -> Material {
        let mut m = Material::default_named("m");
        m.ka = Some(Vec3::splat(1.0));
        m.kd = Vec3::splat(0.5);
        m.ks = Vec3::splat(0.25);
        m.ke = Vec3::new(0.1, 0.0, 0.0);
        m.ns = 8.0;
        m.illum = illum;
        m
    }

    #[test]
    fn matches_the_formula_for_a_light_straight_above() {
        let lights = [Light {
            kind: LightKind::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: 4.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        }];
        let shadows = Shadows::none();
        let mut ctx = context(&shadows, crate::scene::settings::ShadingMode::BlinnPhong);
        ctx.lights = &lights;
        ctx.ambient = Vec3::splat(0.1);
        ctx.eye = Vec3::new(0.0, 5.0, 0.0);
        let at = |n: Vec3, illum: u8| -> Vec3 {
            let f = Lanes::<f32> {
                position: V3::from(Vec3::ZERO),
                normal: V3::from(n),
                color: None,
                geo_normal: [n; 8],
                ao: 1.0,
                depth: 5.0,
                edge: f32::INFINITY,
                lights: LightMask::ALL,
                vertex_light: None,
            };
            ctx.shade_blinn_phong(&material(illum), &mut Plain, &f, None)
                .into()
        };
        // E = 4/4 = 1, n.l = 1, n.h = 1
        let l2 = at(Vec3::Y, 2);
        let want = Vec3::new(0.1 + 0.1 + 0.5 + 0.25, 0.1 + 0.5 + 0.25, 0.1 + 0.5 + 0.25);
        assert!((l2 - want).length() < 1e-6, "{l2}");
        let l1 = at(Vec3::Y, 1);
        assert!((l1 - Vec3::new(0.7, 0.6, 0.6)).length() < 1e-6, "{l1}");
        assert_eq!(at(Vec3::Y, 0), Vec3::splat(0.5));
        // A light below the surface adds nothing.
        let below = at(-Vec3::Y, 2);
        assert!(
            (below - Vec3::new(0.2, 0.1, 0.1)).length() < 1e-6,
            "{below}"
        );
    }
}
