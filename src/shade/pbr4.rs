//! Metallic-roughness shading of a lane group of fragments at once (see
//! `shade::lanes`): what `ShadeContext::shade` gives a pbr material (base
//! colour, metallic-roughness, occlusion, emissive and tangent-space
//! normal maps; the KHR specular, clearcoat, sheen and iridescence layers
//! of constant factors; every light kind and shadow, ambient, the
//! prefiltered environment), each lane bit for bit the
//! one-fragment code's answer (`pbr::radiance`, `pbr::environment`).
//! Exponentials, the environment's BRDF table and its prefiltered levels
//! (whose roughness differs from lane to lane) are looked up per lane.

use std::f32::consts::PI;

use glam::Vec3;

use super::ShadeContext;
use super::env::{EnvLight, dominant_direction_lanes};
use super::iridescence::Iridescence;
use super::lanes::{Kind, Lanes, Lit, Lookups, MAX_LANES, MapSet, PbrMaps, same_lookup};
use super::sheen::Sheen;
use crate::scene::Material;
use crate::simd::{Lane, Mask, V3, clamp01};

impl<'a> Kind<'a> {
    /// A metallic-roughness material's maps, or None where the lanes do
    /// not take it (separate roughness or metallic maps, transmission, a
    /// specular, clearcoat, sheen or iridescence layer with maps of its
    /// own).
    pub(super) fn pbr(
        m: &'a Material,
        maps: &mut MapSet<'_, 'a>,
        tangents: bool,
    ) -> Option<Kind<'a>> {
        let p = &m.pbr;
        if p.roughness_map.is_some()
            || p.metallic_map.is_some()
            || p.transmission.is_some()
            || p.specular
                .as_ref()
                .is_some_and(|d| d.color_map.is_some() || d.weight_map.is_some())
            || p.clearcoat.as_ref().is_some_and(|k| {
                k.map.is_some() || k.roughness_map.is_some() || k.normal_map.is_some()
            })
            || p.sheen
                .as_ref()
                .is_some_and(|k| k.color_map.is_some() || k.roughness_map.is_some())
            || p.iridescence
                .as_ref()
                .is_some_and(|k| k.map.is_some() || k.thickness_map.is_some())
        {
            return None;
        }
        let base = maps.optional(&p.base_color_map)?;
        let metallic_roughness = maps.optional(&p.metallic_roughness_map)?;
        let occlusion = maps.optional(&p.occlusion_map)?;
        let emissive = if p.emissive == Vec3::ZERO {
            None
        } else {
            maps.optional(&p.emissive_map)?
        };
        let normal = maps.normal(m, tangents)?;
        Some(Kind::Pbr(PbrMaps {
            base,
            metallic_roughness,
            occlusion,
            emissive,
            normal,
        }))
    }
}

/// The coat's reflectance at normal incidence (ior 1.5).
pub(super) const COAT_F0: f32 = 0.04;

/// Smallest alpha: a perfect mirror would make D a delta that point lights
/// never hit; this keeps a tiny, finite highlight.
pub(super) const MIN_ALPHA: f32 = 2e-3;

/// Lagarde's specular occlusion from ambient occlusion `ao`.
#[inline]
pub(super) fn specular_occlusion(ndv: f32, ao: f32, roughness: f32) -> f32 {
    if ao >= 1.0 {
        1.0
    } else {
        ((ndv + ao).powf((-16.0 * roughness - 1.0).exp2()) - 1.0 + ao).clamp(0.0, 1.0)
    }
}

/// `x.powi(5)` per lane: x (x^2 x^2), the products LLVM makes of it.
#[inline(always)]
fn pow5<L: Lane>(x: L) -> L {
    let x2 = x * x;
    x * (x2 * x2)
}

/// A clearcoat of constant factor and roughness over the lanes' points,
/// about the interpolated normals (`pbr::Coat`).
pub(super) struct Coat<L: Lane> {
    /// In (0, 1].
    pub factor: f32,
    pub roughness: f32,
    pub normal: V3<L>,
}

impl<L: Lane> Coat<L> {
    /// `pbr::Coat::weight`: factor times the layer's Fresnel at n.v.
    #[inline(always)]
    pub fn weight(&self, v: V3<L>) -> L {
        let one = L::splat(1.0);
        let ndv = self.normal.dot(v).abs().min(one);
        L::splat(self.factor) * (L::splat(COAT_F0) + L::splat(1.0 - COAT_F0) * pow5(one - ndv))
    }

    /// `pbr::Coat::f_cos`: the layer's BRDF times its cosine, times
    /// factor, for light from `l` (zero where the layer faces away).
    #[inline(always)]
    pub fn f_cos(&self, v: V3<L>, l: V3<L>) -> L {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let nc = self.normal;
        let ndl = nc.dot(l);
        let h = (l + v).normalize_or(V3::zero());
        let fresnel = L::splat(COAT_F0) + L::splat(1.0 - COAT_F0) * pow5(one - v.dot(h).abs());
        let a = (self.roughness * self.roughness).max(MIN_ALPHA);
        let f = L::splat(self.factor) * fresnel * d_vis(nc, v, h, ndl, L::splat(a * a)) * ndl;
        L::select(ndl.cmple(zero), zero, f)
    }
}

/// Metallic-roughness points, one per lane, as `PbrColor` holds one
/// (without the layers the lanes do not take).
pub(super) struct Color<L: Lane> {
    pub roughness: L,
    pub occlusion: L,
    /// `PbrColor::f0`, `f90` and `c_diff` (less the transmitted share).
    pub f0: V3<L>,
    pub f90: L,
    pub c_diff: V3<L>,
    /// alpha^2 of the GGX lobe.
    pub a2: L,
    /// The constant layers (`PbrColor`'s; a film only where its factor
    /// is above 0).
    pub sheen: Option<Sheen>,
    pub iridescence: Option<Iridescence>,
}

impl<'a> ShadeContext<'a> {
    /// `shade` of the lanes' fragments of pbr material `m` with maps
    /// `maps`.
    pub(super) fn pbr_lanes<L: Lane>(
        &self,
        m: &Material,
        maps: &PbrMaps<'a>,
        lookups: &mut Lookups<'_, '_, L>,
        f: &Lanes<'_, L>,
    ) -> V3<L> {
        let p = &m.pbr;
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        // `pbr_color`.
        let mut base = V3::splat(p.base_color.truncate());
        if let Some(map) = &maps.base {
            base = base * lookups.read(map);
        }
        if let Some(c) = f.color {
            base = base * c;
        }
        let mr = maps
            .metallic_roughness
            .as_ref()
            .map(|map| lookups.read(map));
        let (roughness, metallic) = match mr {
            Some(mr) => (L::splat(p.roughness) * mr.y, L::splat(p.metallic) * mr.z),
            None => (L::splat(p.roughness), L::splat(p.metallic)),
        };
        let occlusion = match &maps.occlusion {
            Some(map) => {
                let o = match (&maps.metallic_roughness, mr) {
                    (Some(other), Some(mr)) if same_lookup(map, other) => mr,
                    _ => lookups.read(map),
                };
                one + L::splat(p.occlusion_strength) * (o.x - one)
            }
            None => one,
        };
        let emissive = if p.emissive == Vec3::ZERO {
            V3::zero()
        } else {
            let e = V3::splat(p.emissive);
            match &maps.emissive {
                Some(map) => e * lookups.read(map),
                None => e,
            }
        };
        let (metallic, roughness) = (clamp01(metallic), clamp01(roughness));
        let alpha = (roughness * roughness).max(L::splat(MIN_ALPHA));
        let keep = one - metallic;
        // `pbr_color`'s constant layers (their maps' lookups are 1).
        let dielectric = p.specular.as_ref().map(|d| {
            let weight = d.weight * 1.0;
            ((d.f0 * Vec3::ONE).min(Vec3::ONE) * weight, weight)
        });
        let (f0, f90) = match dielectric {
            None => (Vec3::splat(0.04), one),
            Some((f0, w)) => (f0, L::splat(w) + L::splat(1.0 - w) * metallic),
        };
        let c = Color {
            roughness,
            occlusion,
            // `Vec3::lerp`: f0 (1 - metallic) + base metallic.
            f0: V3::splat(f0).scale(keep) + base.scale(metallic),
            f90,
            c_diff: base.scale(keep),
            a2: alpha * alpha,
            sheen: p.sheen.as_ref().map(|k| Sheen {
                color: k.color * Vec3::ONE,
                roughness: (k.roughness * 1.0).clamp(0.0, 1.0),
            }),
            iridescence: p.iridescence.as_ref().and_then(|k| {
                let factor = (k.factor * 1.0).clamp(0.0, 1.0);
                (factor > 0.0).then_some(Iridescence {
                    factor,
                    ior: k.ior,
                    thickness: k.thickness_max,
                })
            }),
        };

        let v = self.view_lanes(f.position);
        let n = match &maps.normal {
            Some((map, scale)) => self.normal_map_lanes(f, lookups.read(map), *scale),
            None => f.normal,
        };
        // `pbr_color`'s clearcoat (no maps: factor and roughness times 1).
        let coat = p.clearcoat.as_ref().and_then(|k| {
            let factor = (k.factor * 1.0).clamp(0.0, 1.0);
            (factor > 0.0).then(|| Coat {
                factor,
                roughness: (k.roughness * 1.0).clamp(0.0, 1.0),
                normal: f.normal,
            })
        });
        if coat.is_some() || c.sheen.is_some() {
            let out = self.layered_radiance(f, [n, v], &c, coat.as_ref(), emissive);
            return match self.env {
                Some(env) => out + layered_environment(env, [n, v], &c, coat.as_ref(), f.ao),
                None => out,
            };
        }
        // `pbr::radiance`.
        let mut out = emissive;
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, ndl, e, lit } = self.lit_lanes(i, light, f, n);
            if lit.any() {
                let added = out + e * brdf(n, v, l, ndl, &c);
                out = V3::select(lit, added, out);
            }
        });
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let some_ambient = !(ambient.x.cmpeq(zero) & ambient.y.cmpeq(zero) & ambient.z.cmpeq(zero));
        if some_ambient.any() {
            let spec = specular_albedo(&c, n.dot(v).abs());
            let ones = V3::splat(Vec3::ONE);
            let added = out + ambient.scale(c.occlusion) * (c.c_diff * (ones - spec) + spec);
            out = V3::select(some_ambient, added, out);
        }
        match self.env {
            Some(env) => out + environment(env, n, v, &c, f.ao),
            None => out,
        }
    }
}

impl ShadeContext<'_> {
    /// `pbr::layered_radiance` at the lanes' points, normals and view
    /// vectors `[n, v]`, with a sheen (`c.sheen`) or a clearcoat `coat`:
    /// each light through `f_cos`, the base's ambient term scaled by the
    /// sheen plus the sheen's own, then (with the emission) under the
    /// coat, plus the coat's ambient term.
    #[inline(always)]
    fn layered_radiance<L: Lane>(
        &self,
        f: &Lanes<'_, L>,
        [n, v]: [V3<L>; 2],
        c: &Color<L>,
        coat: Option<&Coat<L>>,
        emissive: V3<L>,
    ) -> V3<L> {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let w = coat.map(|k| k.weight(v));
        let ndv = n.dot(v).abs();
        let mut direct = V3::zero();
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, ndl, e, lit } = self.lit_lanes(i, light, f, n);
            if lit.any() {
                // `f_cos` over n.l (e carries n.l).
                let ndl_0 = ndl.max(zero);
                let mut base = brdf(n, v, l, ndl, c).scale(ndl_0);
                if let Some(s) = &c.sheen {
                    let k = L::from_fn(|k| s.scaling(ndv.lane(k), Some(ndl_0.lane(k))));
                    let lobe = L::from_fn(|k| s.lobe_cos(n.lane(k), v.lane(k), l.lane(k)));
                    base = base.scale(k) + V3::splat(s.color).scale(lobe);
                }
                let layered = match (coat, w) {
                    (Some(coat), Some(w)) => base.scale(one - w) + splat3(coat.f_cos(v, l)),
                    _ => base,
                };
                let added = direct + e * (layered / ndl);
                direct = V3::select(lit, added, direct);
            }
        });
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let some_ambient = !(ambient.x.cmpeq(zero) & ambient.y.cmpeq(zero) & ambient.z.cmpeq(zero));
        let mut under = V3::zero();
        if some_ambient.any() {
            let spec = specular_albedo(c, ndv);
            let ones = V3::splat(Vec3::ONE);
            // c_diff (1 - transmission), transmission 0.
            let c_diff = c.c_diff.scale(one - zero);
            let mut lit = ambient.scale(c.occlusion) * (c_diff * (ones - spec) + spec);
            if let Some(s) = &c.sheen {
                let k = L::from_fn(|k| s.scaling(ndv.lane(k), None));
                let own = V3::from_fn(|k| s.reflectance(ndv.lane(k)));
                lit = lit.scale(k) + ambient.scale(c.occlusion) * own;
            }
            under = V3::select(some_ambient, lit, under);
        }
        under = under + emissive;
        if let (Some(coat), Some(w)) = (coat, w) {
            under = under.scale(one - w);
            if some_ambient.any() {
                // `specular_albedo` of F0 0.04 (F90 1) at the coat's n.v.
                let (a, b) = env_brdf(L::splat(coat.roughness), coat.normal.dot(v).abs());
                let s = clamp01(L::splat(COAT_F0) * a + b * one);
                let added =
                    under + (ambient.scale(c.occlusion) * splat3(s)).scale(L::splat(coat.factor));
                under = V3::select(some_ambient, added, under);
            }
        }
        under + direct
    }
}

/// The same value in x, y and z.
#[inline(always)]
fn splat3<L: Lane>(x: L) -> V3<L> {
    V3 { x, y: x, z: x }
}

/// The environment's light at the lanes' points, normals and view vectors
/// `[n, v]` (`pbr::environment` is its one-lane instance), with a sheen
/// (`c.sheen`) or a clearcoat `coat`: the base scaled by the sheen plus
/// the sheen's lobe, under the coat, plus the coat's prefiltered lobe
/// about its normal.
#[inline(always)]
pub(super) fn layered_environment<L: Lane>(
    env: &EnvLight,
    [n, v]: [V3<L>; 2],
    c: &Color<L>,
    coat: Option<&Coat<L>>,
    ao: L,
) -> V3<L> {
    let mut base = environment(env, n, v, c, ao);
    if let Some(s) = &c.sheen {
        let ndv = n.dot(v).abs().max(L::splat(1e-4));
        let irradiance = env.irradiance_lanes(n);
        let lobe = V3::from_fn(|k| irradiance.lane(k) * (s.reflectance(ndv.lane(k)) / PI));
        let k = L::from_fn(|k| s.scaling(ndv.lane(k), None));
        base = base.scale(k) + lobe.scale(ao.min(L::splat(1.0)) * c.occlusion);
    }
    let Some(coat) = coat else {
        return base;
    };
    let nc = coat.normal;
    let ndv = nc.dot(v).abs().max(L::splat(1e-4));
    let (mut a, mut b) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
    for k in 0..L::WIDTH {
        let ab = env.brdf(ndv.lane(k), coat.roughness);
        (a[k], b[k]) = (ab.x, ab.y);
    }
    let (a, b) = (L::from_fn(|k| a[k]), L::from_fn(|k| b[k]));
    let r = nc.scale(L::splat(2.0) * nc.dot(v)) - v;
    let r = dominant_direction_lanes(nc, r, L::splat(coat.roughness));
    let so = L::from_fn(|k| specular_occlusion(ndv.lane(k), ao.lane(k), coat.roughness));
    let layer = env
        .prefiltered_lanes(r, coat.roughness)
        .scale((L::splat(COAT_F0) * a + b) * so);
    base.scale(L::splat(1.0) - coat.weight(v)) + layer.scale(L::splat(coat.factor) * c.occlusion)
}

/// The base layer's BRDF at the lanes' points, for unit light directions
/// `l` with n.l = `ndl` > 0 (`pbr::brdf` is its one-lane instance).
#[inline(always)]
pub(super) fn brdf<L: Lane>(n: V3<L>, v: V3<L>, l: V3<L>, ndl: L, c: &Color<L>) -> V3<L> {
    let h = (l + v).normalize_or(V3::zero());
    let vdh = v.dot(h).abs();
    let one = V3::splat(Vec3::ONE);
    let mut fresnel = c.f0 + (splat3(c.f90) - c.f0).scale(pow5(L::splat(1.0) - vdh));
    if let Some(film) = &c.iridescence {
        fresnel = V3::from_fn(|k| film.blend(fresnel.lane(k), vdh.lane(k), c.f0.lane(k)));
    }
    (one - fresnel) * c.c_diff / L::splat(PI) + fresnel.scale(d_vis(n, v, h, ndl, c.a2))
}

/// GGX's D times the separable Smith visibility for n.l = `ndl` > 0 and
/// half vector `h`, per lane (`pbr::d_vis` is its one-lane instance).
#[inline(always)]
pub(super) fn d_vis<L: Lane>(n: V3<L>, v: V3<L>, h: V3<L>, ndl: L, a2: L) -> L {
    let (zero, one) = (L::splat(0.0), L::splat(1.0));
    let ndv = n.dot(v).abs().max(L::splat(1e-4));
    let ndh = n.dot(h);
    let t = ndh * ndh * (a2 - one) + one;
    let d = L::select(ndh.cmpgt(zero), a2 / (L::splat(PI) * t * t), zero);
    let vis = one
        / ((ndl + (a2 + (one - a2) * ndl * ndl).sqrt())
            * (ndv + (a2 + (one - a2) * ndv * ndv).sqrt()));
    d * vis
}

/// The split sum's specular albedo f0 a + f90 b, with a film blended
/// towards its Fresnel at n.v = `ndv` times the lobe's albedo a + b
/// (`PbrColor::split_sum` is its one-lane instance).
#[inline(always)]
pub(super) fn split_sum<L: Lane>(c: &Color<L>, ndv: L, a: L, b: L) -> V3<L> {
    let s = c.f0.scale(a) + splat3(b * c.f90);
    match &c.iridescence {
        Some(film) => V3::from_fn(|k| {
            let f = film.fresnel(ndv.lane(k), c.f0.lane(k)).min(Vec3::ONE);
            s.lane(k).lerp(f * (a.lane(k) + b.lane(k)), film.factor)
        }),
        None => s,
    }
}

/// `PbrColor::specular_albedo` at n.v = `ndv`: the split sum of the
/// analytic fit, clamped to [0, 1].
#[inline(always)]
fn specular_albedo<L: Lane>(c: &Color<L>, ndv: L) -> V3<L> {
    let (a, b) = env_brdf(c.roughness, ndv);
    let spec = split_sum(c, ndv, a, b);
    V3 {
        x: clamp01(spec.x),
        y: clamp01(spec.y),
        z: clamp01(spec.z),
    }
}

/// The analytic fit of the environment BRDF's scale and bias of f0, per
/// lane (`pbr::env_brdf` is its one-lane instance).
#[inline(always)]
pub(super) fn env_brdf<L: Lane>(roughness: L, ndv: L) -> (L, L) {
    let r = clamp01(roughness);
    let k = L::splat;
    let (x, y, z, w) = (
        -r + k(1.0),
        k(-0.0275) * r + k(0.0425),
        k(-0.572) * r + k(1.04),
        k(0.022) * r - k(0.04),
    );
    let e = ndv.map(|n| (-9.28 * n.max(0.0)).exp2());
    let a004 = (x * x).min(e) * x + y;
    (k(-1.04) * a004 + z, k(1.04) * a004 + w)
}

/// `pbr::environment` at the lanes' points, without the sheen and the
/// clearcoat (`layered_environment` adds them).
#[inline(always)]
fn environment<L: Lane>(env: &EnvLight, n: V3<L>, v: V3<L>, c: &Color<L>, ao: L) -> V3<L> {
    let ndv = n.dot(v).abs().max(L::splat(1e-4));
    let (mut a, mut b) = ([0.0f32; MAX_LANES], [0.0f32; MAX_LANES]);
    for k in 0..L::WIDTH {
        let ab = env.brdf(ndv.lane(k), c.roughness.lane(k));
        (a[k], b[k]) = (ab.x, ab.y);
    }
    let spec = split_sum(c, ndv, L::from_fn(|k| a[k]), L::from_fn(|k| b[k]));
    let one = V3::splat(Vec3::ONE);
    let diffuse = (c.c_diff * (one - spec) * env.irradiance_lanes(n)).scale(ao / L::splat(PI));
    let r = n.scale(L::splat(2.0) * n.dot(v)) - v;
    let r = dominant_direction_lanes(n, r, c.roughness);
    let light = V3::from_fn(|k| env.prefiltered(r.lane(k), c.roughness.lane(k)));
    let so = L::from_fn(|k| specular_occlusion(ndv.lane(k), ao.lane(k), c.roughness.lane(k)));
    let specular = (light * spec).scale(so);
    (diffuse + specular).scale(c.occlusion)
}

#[cfg(test)]
#[allow(clippy::needless_range_loop)]
mod tests {
    use super::*;
    use crate::shade::pbr::{self, PbrColor};
    use crate::testing::xorshift;
    use glam::Vec4;

    #[test]
    fn pow5_is_powi_bit_for_bit() {
        let mut next = xorshift(0x2545_f491_4f6c_dd1d);
        let mut xs: Vec<f32> = (0..100_000).map(|_| next() * 2.0 - 0.5).collect();
        xs.extend([0.0, -0.0, 1.0, 1e-30, 1e30, f32::MIN_POSITIVE, 0.999_999_9]);
        for x in xs {
            let got = pow5(Vec4::splat(x)).x;
            assert_eq!(got.to_bits(), x.powi(5).to_bits(), "{x}");
        }
    }

    /// Random unit vectors in the upper hemisphere of +Z.
    fn hemisphere(next: &mut impl FnMut() -> f32) -> Vec3 {
        loop {
            let d = Vec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next());
            if d.length_squared() > 1e-4 && d.length_squared() <= 1.0 {
                return d.normalize();
            }
        }
    }

    #[test]
    fn brdf_and_ambient_fit_are_the_scalar_ones_bit_for_bit() {
        let mut next = xorshift(0x9e37_79b9_7f4a_7c15);
        for _ in 0..5_000 {
            let mut lanes = Vec::new();
            for _ in 0..4 {
                let n = hemisphere(&mut next);
                let (v, l) = (hemisphere(&mut next), hemisphere(&mut next));
                let color = PbrColor {
                    base: Vec3::new(next(), next(), next()),
                    metallic: next(),
                    roughness: next(),
                    occlusion: 1.0,
                    emissive: Vec3::ZERO,
                    dielectric: None,
                    coat: None,
                    sheen: None,
                    transmission: 0.0,
                    attenuation: Vec3::ONE,
                    iridescence: None,
                };
                lanes.push((n, v, l, color));
            }
            let at = |f: fn(&(Vec3, Vec3, Vec3, PbrColor)) -> Vec3| {
                V3::from_lanes([0, 1, 2, 3].map(|k| f(&lanes[k])))
            };
            let per = |f: fn(&(Vec3, Vec3, Vec3, PbrColor)) -> f32| {
                Vec4::from([0, 1, 2, 3].map(|k| f(&lanes[k])))
            };
            let (n, v, l) = (at(|x| x.0), at(|x| x.1), at(|x| x.2));
            let metallic = per(|x| x.3.metallic);
            let roughness = per(|x| x.3.roughness);
            let base = at(|x| x.3.base);
            let alpha = (roughness * roughness).max(Vec4::splat(MIN_ALPHA));
            let keep = Vec4::ONE - metallic;
            let c = Color {
                roughness,
                occlusion: Vec4::ONE,
                f0: V3::splat(Vec3::splat(0.04)).scale(keep) + base.scale(metallic),
                f90: Vec4::ONE,
                c_diff: base.scale(keep),
                a2: alpha * alpha,
                sheen: None,
                iridescence: None,
            };
            let ndl = n.dot(l);
            let got = brdf(n, v, l, ndl, &c);
            let (a, b) = env_brdf(roughness, n.dot(v).abs());
            let albedo = split_sum(&c, n.dot(v).abs(), a, b);
            for k in 0..4 {
                let (n, v, l, color) = &lanes[k];
                if n.dot(*l) <= 0.0 {
                    continue;
                }
                let want = pbr::brdf(*n, *v, *l, color);
                let bits = |x: Vec3| x.to_array().map(f32::to_bits);
                assert_eq!(bits(got.lane(k)), bits(want), "{got:?} lane {k}: {want}");
                let fit = color.specular_albedo(n.dot(*v).abs());
                let lane = albedo.lane(k).clamp(Vec3::ZERO, Vec3::ONE);
                assert_eq!(bits(lane), bits(fit), "{lane} against {fit}");
            }
        }
    }
}
