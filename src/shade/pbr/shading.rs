//! A metallic-roughness material shaded at the lanes' points: its factors
//! times its maps (`pbr_color`), every light with its shadow, the ambient
//! term and the environment (prefiltered or sampled), written once over
//! the lane type.

use glam::Vec3;

use super::{
    Aniso, COAT_F0, Coat, Films, PbrColor, Sheens, brdf, btdf, env_brdf, environment, f_cos, splat3,
};
use crate::scene::Material;
use crate::scene::light::{Light, LightKind};
use crate::shade::env::reflect::At;
use crate::shade::env::sampled::{self as env_sampled, Lobes};
use crate::shade::lanes::{Lanes, Lit};
use crate::shade::{Fetch, MAX_SPREAD, ShadeContext};
use crate::simd::{Lane, Mask, V3, clamp01};

/// Where a normal map's spread (`Fetch::normal_spread`: the squared turn
/// of the mapped normal over a pixel's step along each axis, summed) is
/// more than this many times the lobe's alpha^2, the map's detail is far
/// sharper than the lobe, and `prefiltered` shades four normals of the
/// pixel (the lights and the environment; `sampled`, its environment,
/// always). The bumpy metal ball against Cycles: 0.130 -> 0.109
/// (courtyard), 0.130 -> 0.103 (studio) FLIP. In FlightHelmet 0.6% of the
/// shaded groups take it (16 times alpha^2: 2.4%, with no gain).
const FAST_TURN: f32 = 64.0;
/// The least alpha^2 `FAST_TURN` compares with.
const MIN_LOBE: f32 = 1e-4;

/// `one()` in the lanes `fast` leaves clear; in the others, the mean of
/// `shade` over the pixel's four normals `ns`. `four`: `(ns, fast)`, or
/// None for `one()` everywhere. Where every lane is fast, `one` is not
/// shaded at all.
#[inline(always)]
fn over_pixel<L: Lane>(
    four: Option<([V3<L>; 4], L::Mask)>,
    one: impl FnOnce() -> V3<L>,
    mut shade: impl FnMut(V3<L>) -> V3<L>,
) -> V3<L> {
    let Some((ns, fast)) = four else {
        return one();
    };
    let mean = ns
        .iter()
        .fold(V3::zero(), |sum, &n| sum + shade(n))
        .scale(L::splat(0.25));
    if fast.all() {
        return mean;
    }
    V3::select(fast, mean, one())
}

impl<L: Lane> PbrColor<L> {
    /// Lane `k`'s point alone.
    pub fn at(&self, k: usize) -> PbrColor<f32> {
        let v = |x: V3<L>| V3::from(x.lane(k));
        PbrColor {
            base: v(self.base),
            metallic: self.metallic.lane(k),
            roughness: self.roughness.lane(k),
            occlusion: self.occlusion.lane(k),
            emissive: v(self.emissive),
            f0: v(self.f0),
            f90: self.f90.lane(k),
            c_diff: v(self.c_diff),
            a2: self.a2.lane(k),
            transmission: self.transmission.lane(k),
            attenuation: v(self.attenuation),
            volume: (self.volume.0.lane(k), self.volume.1, self.volume.2),
            coat: self.coat.map(|c| Coat {
                factor: c.factor.lane(k),
                roughness: c.roughness.lane(k),
                normal: v(c.normal),
            }),
            sheen: self.sheen.map(|s| Sheens {
                color: v(s.color),
                roughness: s.roughness.lane(k),
            }),
            iridescence: self.iridescence.map(|f| Films {
                factor: f.factor.lane(k),
                ior: f.ior,
                thickness: f.thickness.lane(k),
            }),
            behind: self.behind.map(v),
            aniso: self.aniso.map(|a| Aniso {
                dir: (a.dir.0.lane(k), a.dir.1.lane(k)),
                strength: a.strength.lane(k),
                t: v(a.t),
                b: v(a.b),
                at: a.at.lane(k),
                ab: a.ab.lane(k),
            }),
        }
    }
}

/// `factor` times the red of `t`'s texels, where there are any.
#[inline(always)]
fn times<L: Lane>(factor: f32, texel: Option<V3<L>>, channel: fn(V3<L>) -> L) -> L {
    match texel {
        Some(c) => L::splat(factor) * channel(c),
        None => L::splat(factor),
    }
}

/// The diffuse lobe's albedo under light from every direction: c_diff,
/// plus what the diffuse transmission lets through from behind.
#[inline(always)]
fn diffuse_albedo<L: Lane>(c: &PbrColor<L>) -> V3<L> {
    match c.behind {
        Some(behind) => c.c_diff + behind,
        None => c.c_diff,
    }
}

/// KHR_materials_anisotropy at the lanes' points: the direction (the
/// map's red and green times two minus one, unit; (1, 0) without a map or
/// where the map's is zero) turned by the rotation, and the strength
/// times the map's blue.
#[inline(always)]
fn anisotropy<L: Lane>(
    a: &crate::scene::material::Anisotropy,
    texel: Option<V3<L>>,
    roughness: L,
) -> Aniso<L> {
    let (one, two) = (L::splat(1.0), L::splat(2.0));
    let (x, y, strength) = match texel {
        Some(t) => {
            let (x, y) = (t.x * two - one, t.y * two - one);
            let len = (x * x + y * y).sqrt();
            let some = len.cmpgt(L::splat(1e-6));
            let inv = one / L::select(some, len, one);
            (
                L::select(some, x * inv, one),
                L::select(some, y * inv, L::splat(0.0)),
                L::splat(a.strength) * t.z,
            )
        }
        None => (one, L::splat(0.0), L::splat(a.strength)),
    };
    let (cos, sin) = (L::splat(a.rotation.cos()), L::splat(a.rotation.sin()));
    let dir = (cos * x - sin * y, sin * x + cos * y);
    Aniso::new(dir, clamp01(strength), roughness)
}

/// The lanes' triangle normals, each on the side of the view direction
/// `v`.
fn geometric_towards<L: Lane>(f: &Lanes<L>, v: V3<L>) -> V3<L> {
    let ng = V3::from_fn(|k| f.geo_normal[k]);
    let toward = ng.dot(v).cmpge(L::splat(0.0));
    V3::select(toward, ng, -ng)
}

/// The shading normal `n` turned towards the geometric normal `ng` (on
/// the viewer's side) just far enough that the mirror reflection of the
/// view direction `v` stays above the surface: at least min(0.9 v.ng,
/// 0.01) above its plane. A normal map can tilt `n` so far that the
/// reflection points into the surface, where it would fetch light from
/// below the horizon; Blender Cycles raises the normal of its glossy
/// lobes this way, and so does softraster for every lobe of a
/// normal-mapped metallic-roughness material (`docs/cycles.md`: the
/// bumpy ball's bright rims). Interpolated normals are left as they are:
/// raising them changed no frame of the Cycles set.
///
/// In the plane of `ng` (z) and the part of `n` across it (x), the
/// raised normal (sqrt(1 - z^2), z) reflects `v` to height t where
/// 4 a z^4 - 2 b z^2 + c = 0, a = vx^2 + vz^2, b = 2 (a + vz t),
/// c = (vz + t)^2; of its roots the one with the sign of vx is taken.
pub(crate) fn valid_reflection<L: Lane>(ng: V3<L>, v: V3<L>, n: V3<L>) -> V3<L> {
    let zero = L::splat(0.0);
    let r = n.scale(L::splat(2.0) * n.dot(v)) - v;
    let vz = v.dot(ng).max(zero);
    let t = (L::splat(0.9) * vz).min(L::splat(0.01));
    let x = (n - ng.scale(n.dot(ng))).normalize_or(n);
    let vx = v.dot(x);
    let a = vx * vx + vz * vz;
    // (A view along the surface, across the tilt, has a = 0: no raised
    // normal is defined there, and it is left as it is.)
    let low = r.dot(ng).cmplt(t) & a.cmpgt(L::splat(1e-12));
    if !low.any() {
        return n;
    }
    let b = L::splat(2.0) * (a + vz * t);
    let c = (t + vz) * (t + vz);
    let root = (b * b - L::splat(4.0) * a * c).max(zero).sqrt();
    let z2 = L::select(vx.cmplt(zero), b + root, b - root) * L::splat(0.25) / a;
    let z2 = clamp01(z2);
    let raised = x.scale((L::splat(1.0) - z2).sqrt()) + ng.scale(z2.sqrt());
    V3::select(low, raised, n)
}

impl ShadeContext<'_> {
    /// Whether the environment's light is found by rays that see what
    /// hides it: `sampled`, or the prefiltered bounce.
    fn traces_occlusion(&self) -> bool {
        self.env_sampled.is_some() || self.env_reflections.is_some_and(|r| r.bounce)
    }

    /// The material's metallic-roughness factors times its maps (and the
    /// vertex colour) at the lanes' points.
    pub(crate) fn pbr_color<L: Lane>(
        &self,
        m: &Material,
        fetch: &mut impl Fetch<L>,
        f: &Lanes<L>,
    ) -> PbrColor<L> {
        let p = &m.pbr;
        let one = L::splat(1.0);
        let mut base = V3::splat(p.base_color.truncate());
        if let Some(c) = fetch.rgb_of(&p.base_color_map) {
            base = base * c;
        }
        if let Some(c) = f.color {
            base = base * c;
        }
        let mr = fetch.rgb_of(&p.metallic_roughness_map);
        let mut roughness = times(p.roughness, mr, |c| c.y);
        let mut metallic = times(p.metallic, mr, |c| c.z);
        if let Some(r) = fetch.rgb_of(&p.roughness_map) {
            roughness = roughness * r.x;
        }
        if let Some(x) = fetch.rgb_of(&p.metallic_map) {
            metallic = metallic * x.x;
        }
        let mut c = PbrColor::new(base, clamp01(metallic), clamp01(roughness));
        // A baked occlusion map stands for the rays the split sum does
        // not cast; where rays find what hides the environment (`sampled`,
        // the prefiltered bounce) it would count it twice, as a path
        // tracer does not.
        if !self.traces_occlusion()
            && let Some(o) = fetch.rgb_of(&p.occlusion_map)
        {
            c.occlusion = one + L::splat(p.occlusion_strength) * (o.x - one);
        }
        if p.emissive != Vec3::ZERO {
            c.emissive = V3::splat(p.emissive);
            if let Some(e) = fetch.rgb_of(&p.emissive_map) {
                c.emissive = c.emissive * e;
            }
        }
        if let Some(d) = &p.specular {
            let mut f0 = V3::splat(d.f0);
            if let Some(color) = fetch.rgb_of(&d.color_map) {
                f0 = f0 * color;
            }
            let weight = match fetch.rgba_of(&d.weight_map) {
                Some((_, a)) => L::splat(d.weight) * a,
                None => L::splat(d.weight),
            };
            c.set_dielectric(f0.min(V3::splat(Vec3::ONE)).scale(weight), weight);
        }
        if let Some(k) = &p.clearcoat {
            let factor = clamp01(times(k.factor, fetch.rgb_of(&k.map), |c| c.x));
            // Whether there is a coat is the material's to say (lanes of
            // one call never take different paths).
            if k.map.is_some() || k.factor.clamp(0.0, 1.0) > 0.0 {
                let rough = times(k.roughness, fetch.rgb_of(&k.roughness_map), |c| c.y);
                c.coat = Some(Coat {
                    factor,
                    roughness: clamp01(rough),
                    normal: match &k.normal_map {
                        Some(map) => fetch.normal(map),
                        None => f.normal,
                    },
                });
            }
        }
        if let Some(t) = &p.transmission {
            let factor = clamp01(times(t.factor, fetch.rgb_of(&t.map), |c| c.x));
            let thickness = times(t.thickness, fetch.rgb_of(&t.thickness_map), |c| c.y);
            let (color, distance) = (t.attenuation_color, t.attenuation_distance);
            let beer = |thickness: f32| {
                if distance.is_finite() && thickness > 0.0 {
                    let k = thickness / distance;
                    Vec3::new(color.x.powf(k), color.y.powf(k), color.z.powf(k))
                } else {
                    Vec3::ONE
                }
            };
            // Without a thickness map every lane has the same thickness.
            let attenuation = match t.thickness_map {
                None => V3::splat(beer(thickness.lane(0))),
                Some(_) => V3::from_fn(|k| beer(thickness.lane(k))),
            };
            c.set_transmission(factor, attenuation);
            c.volume = (thickness, t.ior, t.dispersion);
        }
        if let Some(k) = &p.sheen {
            let mut color = V3::splat(k.color);
            if let Some(t) = fetch.rgb_of(&k.color_map) {
                color = color * t;
            }
            let rough = match fetch.rgba_of(&k.roughness_map) {
                Some((_, a)) => L::splat(k.roughness) * a,
                None => L::splat(k.roughness),
            };
            c.sheen = Some(Sheens {
                color,
                roughness: clamp01(rough),
            });
        }
        if let Some(k) = &p.iridescence
            && (k.map.is_some() || k.factor.clamp(0.0, 1.0) > 0.0)
        {
            let factor = clamp01(times(k.factor, fetch.rgb_of(&k.map), |c| c.x));
            let thickness = match fetch.rgb_of(&k.thickness_map) {
                Some(t) => {
                    L::splat(k.thickness_min) + L::splat(k.thickness_max - k.thickness_min) * t.y
                }
                None => L::splat(k.thickness_max),
            };
            c.iridescence = Some(Films {
                factor,
                ior: k.ior,
                thickness,
            });
        }
        if let Some(a) = &m.pbr.anisotropy {
            c.aniso = Some(anisotropy(a, fetch.rgb_of(&a.map), c.roughness));
        }
        if let Some(d) = &p.diffuse_transmission {
            let share = match fetch.rgba_of(&d.map) {
                Some((_, a)) => L::splat(d.factor) * a,
                None => L::splat(d.factor),
            };
            let mut color = V3::splat(d.color);
            if let Some(t) = fetch.rgb_of(&d.color_map) {
                color = color * t;
            }
            c.set_diffuse_transmission(clamp01(share), color);
        }
        c
    }

    /// Metallic-roughness shading of material `m` at the lanes' points.
    pub(crate) fn shade_pbr<L: Lane>(
        &self,
        m: &Material,
        fetch: &mut impl Fetch<L>,
        f: &Lanes<L>,
    ) -> V3<L> {
        let c = self.pbr_color(m, fetch, f);
        self.shade_pbr_color(m, fetch, f, &c)
    }

    /// `shade_pbr` of the material's colour `c` (`pbr_color`), already
    /// read.
    #[inline(always)]
    pub(crate) fn shade_pbr_color<L: Lane>(
        &self,
        m: &Material,
        fetch: &mut impl Fetch<L>,
        f: &Lanes<L>,
        c: &PbrColor<L>,
    ) -> V3<L> {
        let mut c = *c;
        let v = self.view_lanes(f.position);
        // `sampled` integrates a normal map's normals over the pixel
        // (`Fetch::normal_samples`) where the lobe is isotropic, with the
        // material as it is, and so does `prefiltered` where the normals
        // turn fast (`FAST_TURN`); elsewhere the lights see the lobe
        // widened.
        let mut spread_normals = None;
        let mut fast = None;
        let mut horizon = None;
        let plain = c;
        let n = match &m.normal_map {
            Some(map) => {
                let mapped = fetch.normal(map);
                let towards = geometric_towards(f, v);
                horizon = Some(towards);
                // The spread is the map's own, before any raising.
                let lit = !f.light_set(self.lights).is_empty();
                // Where only `FAST_TURN` reads the spread, lanes whose lobe
                // no spread can pass (at most 2, `Fetch::normal_spread`)
                // need no measure.
                let widens = self.env_sampled.is_some() || lit;
                let wide = L::splat(FAST_TURN) * c.a2.max(L::splat(MIN_LOBE));
                let may_be_fast = !wide.cmpge(L::splat(MAX_SPREAD)).all();
                let spread = ((self.env.is_some() && may_be_fast) || widens)
                    .then(|| fetch.normal_spread(map, mapped));
                // Four normals of the pixel: always under `sampled`, and
                // under `prefiltered` where the map turns fast across it.
                // Lane by lane, so that every lane width shades alike.
                fast = spread.map(|s| s.cmpgt(wide));
                let any_fast = fast.is_some_and(|m| m.any());
                if (self.env_sampled.is_some() || any_fast) && c.aniso.is_none() {
                    spread_normals = fetch
                        .normal_samples(map)
                        .map(|ns| ns.map(|m| valid_reflection(towards, v, m)));
                }
                // The widened lobe is the lights' and the sampled
                // environment's: without either, not measured at all.
                if let Some(spread) = spread.filter(|_| widens) {
                    c.widen(spread);
                }
                // Tilted by the map, the normal may reflect the view
                // into the surface: raised as a path tracer raises it.
                valid_reflection(towards, v, mapped)
            }
            None => f.normal,
        };
        if let Some(a) = &mut c.aniso {
            // Without tangents (no texture coordinates) the lobe has no
            // direction: isotropic.
            match fetch.tangents() {
                Some(tangents) => a.orient(n, tangents),
                None => c.aniso = None,
            }
        }
        // Under `prefiltered`, the lights too read the four normals where
        // the map turns fast, with the lobe as it is.
        let four = spread_normals
            .zip(fast)
            .filter(|_| self.env_sampled.is_none());
        let direct = over_pixel(
            four,
            || self.direct(f, [n, v], &c),
            |n| self.direct(f, [n, v], &plain),
        );
        if let Some(sampled) = &self.env_sampled {
            let l = V3::from_fn(|k| match &spread_normals {
                Some(ns) => {
                    let ns = ns.map(|n| n.lane(k));
                    let point = (f.position.lane(k), &ns[..], f.geo_normal[k]);
                    env_sampled::radiance(sampled, point, v.lane(k), &Lobes::Pbr(&plain.at(k)))
                }
                None => {
                    let point = (f.position.lane(k), &[n.lane(k)][..], f.geo_normal[k]);
                    env_sampled::radiance(sampled, point, v.lane(k), &Lobes::Pbr(&c.at(k)))
                }
            });
            return direct + l.scale(c.occlusion);
        }
        match self.env {
            Some(env) => {
                let traced = self.env_reflections.as_ref().map(|with| At {
                    with,
                    position: f.position,
                    geo_normal: &f.geo_normal[..],
                });
                let light = || environment(env, [n, v], &c, f.ao, traced.as_ref(), horizon);
                direct
                    + over_pixel(four, light, |n| {
                        environment(env, [n, v], &plain, f.ao, traced.as_ref(), horizon)
                    })
            }
            None => direct,
        }
    }

    /// The lights' radiance with the material's layers, plus the
    /// emission.
    #[inline(always)]
    fn direct<L: Lane>(&self, f: &Lanes<L>, nv: [V3<L>; 2], c: &PbrColor<L>) -> V3<L> {
        if c.coat.is_some() || c.sheen.is_some() {
            self.layered_radiance(f, nv, c)
        } else {
            self.radiance(f, nv, c)
        }
    }

    /// The lights' and the ambient light's radiance towards `v` at the
    /// points with unit normals `n`, plus the emission (without layers).
    #[inline(always)]
    fn radiance<L: Lane>(&self, f: &Lanes<L>, [n, v]: [V3<L>; 2], c: &PbrColor<L>) -> V3<L> {
        let zero = L::splat(0.0);
        let mut out = c.emissive;
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, ndl, e, lit } = self.lit_lanes(i, light, f, n);
            if lit.any() {
                let mut widened = None;
                let c = seen_by(c, light, f.position, &mut widened);
                let added = out + e * brdf(n, v, l, ndl, c);
                out = V3::select(lit, added, out);
            }
        });
        if let Some(behind) = c.behind {
            out = out + self.behind_radiance(f, [n, v], c, behind);
        }
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let some_ambient = !(ambient.x.cmpeq(zero) & ambient.y.cmpeq(zero) & ambient.z.cmpeq(zero));
        if some_ambient.any() {
            let spec = c.specular_albedo(n.dot(v).abs());
            let ones = V3::splat(Vec3::ONE);
            let added =
                out + ambient.scale(c.occlusion) * (diffuse_albedo(c) * (ones - spec) + spec);
            out = V3::select(some_ambient, added, out);
        }
        out
    }

    /// The lights behind the surface, let through by its diffuse
    /// transmission of colour `behind`.
    #[inline(always)]
    fn behind_radiance<L: Lane>(
        &self,
        f: &Lanes<L>,
        [n, v]: [V3<L>; 2],
        c: &PbrColor<L>,
        behind: V3<L>,
    ) -> V3<L> {
        let mut out = V3::zero();
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, e, lit, .. } = self.lit_behind(i, light, f, n);
            if lit.any() {
                let added = out + e * btdf(n, v, l, behind, c);
                out = V3::select(lit, added, out);
            }
        });
        out
    }

    /// `radiance` with a sheen or a clearcoat: each light through `f_cos`,
    /// the base's ambient term scaled by the sheen plus the sheen's own,
    /// then (with the emission) under the coat, plus the coat's ambient
    /// term.
    #[inline(always)]
    fn layered_radiance<L: Lane>(
        &self,
        f: &Lanes<L>,
        [n, v]: [V3<L>; 2],
        c: &PbrColor<L>,
    ) -> V3<L> {
        let (zero, one) = (L::splat(0.0), L::splat(1.0));
        let ndv = n.dot(v).abs();
        let mut direct = V3::zero();
        f.light_set(self.lights).for_each(|i, light| {
            let Lit { l, ndl, e, lit } = self.lit_lanes(i, light, f, n);
            if lit.any() {
                // e carries n.l, and so does f_cos.
                let mut widened = None;
                let c = seen_by(c, light, f.position, &mut widened);
                let added = direct + e * (f_cos(n, v, l, ndl, c) / ndl);
                direct = V3::select(lit, added, direct);
            }
        });
        let ambient = V3::splat(self.ambient).scale(f.ao);
        let some_ambient = !(ambient.x.cmpeq(zero) & ambient.y.cmpeq(zero) & ambient.z.cmpeq(zero));
        let mut under = V3::zero();
        if some_ambient.any() {
            let spec = c.specular_albedo(ndv);
            let ones = V3::splat(Vec3::ONE);
            let mut lit = ambient.scale(c.occlusion) * (diffuse_albedo(c) * (ones - spec) + spec);
            if let Some(s) = &c.sheen {
                let e = s.albedo(ndv);
                let (k, own) = (s.keep(e), s.reflectance(e));
                lit = lit.scale(k) + ambient.scale(c.occlusion) * own;
            }
            under = V3::select(some_ambient, lit, under);
        }
        if let Some(behind) = c.behind {
            under = under + self.behind_radiance(f, [n, v], c, behind);
        }
        under = under + c.emissive;
        if let Some(coat) = &c.coat {
            under = under.scale(one - coat.weight(v));
            if some_ambient.any() {
                // The specular albedo of F0 0.04 (F90 1) at the coat's n.v.
                let (a, b) = env_brdf(coat.roughness, coat.normal.dot(v).abs());
                let s = clamp01(L::splat(COAT_F0) * a + b * one);
                let added = under + (ambient.scale(c.occlusion) * splat3(s)).scale(coat.factor);
                under = V3::select(some_ambient, added, under);
            }
        }
        under + direct
    }
}

/// `c` as `light` sees it from the points `p`: widened by the light's
/// disc (kept in `slot`), if it has one. An area light's disc subtends
/// tan = radius / distance.
#[inline(always)]
fn seen_by<'c, L: Lane>(
    c: &'c PbrColor<L>,
    light: &Light,
    p: V3<L>,
    slot: &'c mut Option<PbrColor<L>>,
) -> &'c PbrColor<L> {
    match light.kind {
        LightKind::Directional { angle, .. } if angle > 0.0 => slot.insert(c.widened(angle)),
        LightKind::Area {
            position, radius, ..
        } if radius > 0.0 => {
            let d = V3::splat(position) - p;
            let w = L::splat(0.5 * radius) / d.dot(d).sqrt();
            slot.insert(c.widened_by(w * w))
        }
        _ => c,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    #[test]
    fn a_reflection_into_the_surface_is_raised_to_the_threshold() {
        let ng = Vec3::Z;
        let v = Vec3::new(0.8, 0.0, 0.6);
        // Tilted so far from the viewer that v reflects into the surface.
        let n = Vec3::new(-0.7, 0.0, 0.714_142_8).normalize();
        let r = 2.0 * n.dot(v) * n - v;
        assert!(r.z < 0.0);
        let raised: Vec3 = valid_reflection(V3::from(ng), V3::from(v), V3::from(n)).into();
        let r = 2.0 * raised.dot(v) * raised - v;
        assert!((raised.length() - 1.0).abs() < 1e-5);
        assert!((r.z - 0.01).abs() < 1e-4, "{r}");
        // Raised in the plane of n and ng, towards ng.
        assert!(raised.y.abs() < 1e-6 && raised.z > n.z && raised.x < 0.0);
        // A view along the surface, across the tilt: left as it is.
        let along = Vec3::Y;
        let kept: Vec3 = valid_reflection(V3::from(ng), V3::from(along), V3::from(n)).into();
        assert_eq!(kept, n);
        // Seen from the other side (vx < 0): the other root.
        let v2 = Vec3::new(-0.8, 0.0, 0.6);
        let n2 = Vec3::new(0.7, 0.0, 0.714_142_8).normalize();
        let raised2: Vec3 = valid_reflection(V3::from(ng), V3::from(v2), V3::from(n2)).into();
        assert!((raised2 - Vec3::new(-raised.x, 0.0, raised.z)).length() < 1e-5);
    }

    #[test]
    fn a_valid_reflection_keeps_its_normal_and_lanes_agree() {
        let ng = Vec3::Z;
        let v = Vec3::new(0.0, 0.6, 0.8);
        let n = Vec3::new(0.1, 0.2, 0.97).normalize();
        let same: Vec3 = valid_reflection(V3::from(ng), V3::from(v), V3::from(n)).into();
        assert_eq!(same, n);
        // A lane that is raised and one that is not, at widths 1 and 4.
        let bent = Vec3::new(0.0, -0.8, 0.6);
        let ns = [n, bent, n, bent];
        let four = valid_reflection::<Vec4>(V3::splat(ng), V3::splat(v), V3::from_lanes(ns));
        for (k, nk) in ns.iter().enumerate() {
            let one: Vec3 = valid_reflection(V3::from(ng), V3::from(v), V3::from(*nk)).into();
            assert_eq!(four.lane(k), one);
        }
    }
}
