//! Blinn-Phong shading of the fragments of a lane call (see `shade::lanes`):
//! what `ShadeContext::shade` gives a Blinn-Phong material (its textured
//! colours, tangent-space normal map, the lights and shadows, ambient,
//! environment), each lane bit for bit the one-fragment code's answer.

use glam::Vec3;

use super::ShadeContext;
use super::lanes::{Kind, Lanes, Lit, Lookups, Map, MapSet};
use crate::scene::Material;
use crate::shade::env::{EnvLight, dominant_direction_lanes};
use crate::simd::{Lane, Mask, V3};

impl<'a> Kind<'a> {
    /// A Blinn-Phong material's maps, or None where the lanes do not take
    /// it (an Ns map, an ambient or emissive map with its own constant).
    pub(super) fn blinn_phong(
        m: &'a Material,
        maps: &mut MapSet<'_, 'a>,
        tangents: bool,
    ) -> Option<Kind<'a>> {
        if m.map_ns.is_some()
            || (m.ka.is_some() && m.map_ka.is_some())
            || (m.ke != Vec3::ZERO && m.map_ke.is_some())
        {
            return None;
        }
        let kd = maps.optional(&m.map_kd)?;
        let ks = if m.illum >= 2 {
            maps.optional(&m.map_ks)?
        } else {
            None
        };
        let normal = maps.normal(m, tangents)?;
        Some(Kind::BlinnPhong { kd, ks, normal })
    }
}

impl<'a> ShadeContext<'a> {
    /// `shade` of the lanes' fragments of Blinn-Phong material `m` with
    /// maps `[kd, ks]` and `normal`.
    pub(super) fn blinn_phong_lanes<L: Lane>(
        &self,
        m: &Material,
        [kd_map, ks_map]: [&Option<Map<'a>>; 2],
        normal: &Option<(Map<'a>, f32)>,
        lookups: &mut Lookups<'_, '_, L>,
        f: &Lanes<'_, L>,
    ) -> V3<L> {
        // `surface_color`: constants times maps times the vertex colour.
        let mut kd = V3::splat(m.kd);
        if let Some(map) = kd_map {
            kd = kd * lookups.read(map);
        }
        if let Some(c) = f.color {
            kd = kd * c;
        }
        if m.illum == 0 {
            return kd;
        }
        let ka = match m.ka {
            Some(ka) => V3::splat(ka),
            None => kd,
        };
        let specular = m.illum >= 2;
        let ks = match (ks_map, specular) {
            (Some(map), true) => V3::splat(m.ks) * lookups.read(map),
            (None, true) => V3::splat(m.ks),
            (_, false) => V3::zero(),
        };
        let v = self.view_lanes(f.position);
        let n = match normal {
            Some((map, scale)) => self.normal_map_lanes(f, lookups.read(map), *scale),
            None => f.normal,
        };

        // `blinn_phong::light_sums`.
        let zero = L::splat(0.0);
        let mut diffuse = V3::zero();
        let mut spec = V3::zero();
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, e, lit, .. } = self.lit_lanes(i, light, f, n);
            diffuse = diffuse + V3::select(lit, e, V3::zero());
            if specular {
                let h = (l + v).normalize_or(V3::zero());
                let ndh = n.dot(h).max(zero);
                let shine = lit & ndh.cmpgt(zero);
                if shine.any() {
                    // Lanes that do not shine give what they give (x = 0:
                    // 2^-126 raised), left out by the select.
                    let pw = L::from_quads(|q| crate::powers::pow4(ndh.quad(q), m.ns));
                    spec = spec + V3::select(shine, e.scale(pw), V3::zero());
                }
            }
        });
        // `blinn_phong::combine`.
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let spec_term = if specular { ks * spec } else { V3::zero() };
        let mut out = V3::splat(m.ke) + ka * ambient + kd * diffuse + spec_term;
        if let Some(env) = self.env {
            out = out + self.env_lanes(env, [n, v, kd, ks], f.ao, m.ns);
        }
        out
    }

    /// `ShadeContext::env_blinn_phong` on the lanes (illum > 0, and not
    /// the sampled environment: those never reach the lanes), at normals,
    /// view vectors, kd and ks `[n, v, kd, ks]`.
    fn env_lanes<L: Lane>(
        &self,
        env: &EnvLight,
        [n, v, kd, ks]: [V3<L>; 4],
        ao: L,
        ns: f32,
    ) -> V3<L> {
        let zero = L::splat(0.0);
        let roughness = crate::scene::material::roughness_from_ns(ns);
        let diffuse = (kd * env.irradiance_lanes(n)).scale(ao / L::splat(std::f32::consts::PI));
        let no_ks = ks.x.cmpeq(zero) & ks.y.cmpeq(zero) & ks.z.cmpeq(zero);
        if no_ks.all() {
            return diffuse;
        }
        let r = n.scale(L::splat(2.0) * n.dot(v)) - v;
        let r = dominant_direction_lanes(n, r, L::splat(roughness));
        let lit = diffuse + ks * env.prefiltered_phong_lanes(r, roughness);
        V3::select(no_ks, diffuse, lit)
    }
}
