//! What a light delivers to a point: direction and irradiance (the
//! inverse square law, KHR_lights_punctual's range window and spot cone;
//! the shading code's lane-wide form is `lanes::incidence`), and which
//! lights can reach a region at all (`may_reach`, `LightSet`: a band's
//! tiles skip the lights that cannot reach them).

use glam::Vec3;

use crate::scene::light::{Light, LightKind};

/// What one light delivers to a shaded point.
#[derive(Debug, Clone, Copy)]
pub struct Incidence {
    /// Unit vector from the point towards the light.
    pub l: Vec3,
    /// Irradiance on a surface facing the light (RGB), before the cosine.
    pub e: Vec3,
}

/// Unit direction to `light` and its irradiance at `p`; None where the
/// light contributes nothing (outside a spot cone, beyond its range, at
/// the light itself).
#[inline]
pub fn incidence(light: &Light, p: Vec3) -> Option<Incidence> {
    match light.kind {
        LightKind::Directional {
            direction,
            irradiance,
            ..
        } => Some(Incidence {
            l: -direction,
            e: light.color * irradiance,
        }),
        LightKind::Point {
            position,
            intensity,
        } => {
            let (l, r2) = towards(position, p)?;
            let w = window(light, r2);
            if w <= 0.0 {
                return None;
            }
            Some(Incidence {
                l,
                e: light.color * (intensity * w / r2),
            })
        }
        LightKind::Spot {
            position,
            direction,
            intensity,
            cos_inner,
            cos_outer,
        } => {
            let (l, r2) = towards(position, p)?;
            let f = spot_falloff(-l.dot(direction), cos_inner, cos_outer);
            let w = window(light, r2);
            if f <= 0.0 || w <= 0.0 {
                return None;
            }
            Some(Incidence {
                l,
                e: light.color * (intensity * f * w / r2),
            })
        }
        LightKind::Area {
            position,
            axis,
            along,
            around,
            radius,
        } => {
            let (l, r2) = towards(position, p)?;
            let f = along * l.dot(axis).abs() + around;
            let w = window(light, r2);
            if f <= 0.0 || w <= 0.0 {
                return None;
            }
            // r^2 + radius^2: a disc's own on-axis law, finite at the disc.
            Some(Incidence {
                l,
                e: light.color * (f * w / (r2 + radius * radius)),
            })
        }
    }
}

/// The unit direction from `p` to a light at `position`, and the squared
/// distance; None at the light itself.
#[inline]
fn towards(position: Vec3, p: Vec3) -> Option<(Vec3, f32)> {
    let d = position - p;
    let r2 = d.length_squared();
    if r2 <= 0.0 {
        return None;
    }
    Some((d / r2.sqrt(), r2))
}

#[inline]
fn window(light: &Light, r2: f32) -> f32 {
    match light.range {
        Some(range) if range > 0.0 => {
            let q = r2 / (range * range);
            let w = (1.0 - q * q).clamp(0.0, 1.0);
            w * w
        }
        _ => 1.0,
    }
}

/// Which of a frame's lights may reach a region: bit i for light i below
/// 63, bit 63 for all lights from 63 on (those are never culled).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct LightMask(pub u64);

impl LightMask {
    pub const ALL: LightMask = LightMask(u64::MAX);
    pub const NONE: LightMask = LightMask(0);
    const REST: u32 = 63;

    /// With light `i` added.
    #[inline]
    pub fn with(self, i: usize) -> LightMask {
        LightMask(self.0 | 1 << (i as u32).min(Self::REST))
    }

    #[inline]
    pub fn union(self, other: LightMask) -> LightMask {
        LightMask(self.0 | other.0)
    }

    /// Whether light `i` is in the set.
    #[cfg(test)]
    pub fn has(self, i: usize) -> bool {
        self.0 & 1 << (i as u32).min(Self::REST) != 0
    }
}

/// A frame's lights and the ones among them a shaded point may receive
/// light from. Every light it leaves out gives the point exactly nothing,
/// so skipping them changes no bit of the result.
#[derive(Debug, Clone, Copy)]
pub struct LightSet<'a> {
    pub lights: &'a [Light],
    pub mask: LightMask,
}

impl<'a> LightSet<'a> {
    /// Whether the set holds no light.
    #[inline(always)]
    pub fn is_empty(&self) -> bool {
        let mut none = true;
        self.for_each(|_, _| none = false);
        none
    }

    /// Calls `f(i, light)` for each light of the set, in index order.
    #[inline(always)]
    pub fn for_each(&self, mut f: impl FnMut(usize, &'a Light)) {
        let lights = self.lights;
        let rest = LightMask::REST as usize;
        let mut m = self.mask.0;
        if lights.len() < rest {
            m &= (1u64 << lights.len()) - 1;
        }
        while m != 0 {
            let b = m.trailing_zeros() as usize;
            m &= m - 1;
            if b < rest {
                f(b, &lights[b]);
            } else {
                for (i, l) in lights.iter().enumerate().skip(rest) {
                    f(i, l);
                }
            }
        }
    }
}

/// Whether `light` may deliver light to some point of the box `lo..hi`
/// (world space): false only where every point of it lies beyond the
/// light's range or outside its spot cone, where `incidence` gives
/// nothing. Conservative by a small margin against rounding.
pub fn may_reach(light: &Light, lo: Vec3, hi: Vec3) -> bool {
    let position = match light.kind {
        LightKind::Directional { .. } => return true,
        LightKind::Point { position, .. }
        | LightKind::Spot { position, .. }
        | LightKind::Area { position, .. } => position,
    };
    if !(lo.is_finite() && hi.is_finite() && position.is_finite()) {
        return true;
    }
    if let Some(range) = light.range.filter(|r| *r > 0.0) {
        // The window is zero from r = range on.
        let d = (lo - position).max(position - hi).max(Vec3::ZERO);
        if d.length_squared() > range * range * 1.001 {
            return false;
        }
    }
    if let LightKind::Spot {
        direction,
        cos_outer,
        ..
    } = light.kind
    {
        // The box's bounding sphere against the cone: outside it when the
        // angle from the axis to the center exceeds the cone's half-angle
        // plus the angle the sphere subtends.
        let center = (lo + hi) * 0.5;
        let radius = (hi - lo).length() * 0.5;
        let to = center - position;
        let dist = to.length();
        if dist <= radius * 1.001 + 1e-6 {
            return true;
        }
        let half = cos_outer.clamp(-1.0, 1.0).acos();
        let spread = (radius / dist).min(1.0).asin();
        let axis = (to / dist).dot(direction).clamp(-1.0, 1.0).acos();
        if axis > half + spread + 1e-3 {
            return false;
        }
        // Tighter for boxes far from round: a point p is inside the cone
        // when d.(p - a) >= cos_outer |p - a|. Over the box, d.(p - a) is
        // at most its value at the best corner and |p - a| at least the
        // distance to the box; a cone narrower than a half-space misses
        // the box when the first is below cos_outer times the second.
        if cos_outer > 0.0 {
            let (a, b) = ((lo - position) * direction, (hi - position) * direction);
            let along = a.max(b).element_sum();
            let near = (lo - position).max(position - hi).max(Vec3::ZERO).length();
            if along < cos_outer * near - 1e-3 * (along.abs() + near) {
                return false;
            }
        }
    }
    true
}

/// KHR_lights_punctual: t = clamp((cos a - cos outer) / (cos inner - cos outer), 0, 1),
/// attenuation t². Equal cone angles give a hard edge.
#[inline]
pub fn spot_falloff(cos_a: f32, cos_inner: f32, cos_outer: f32) -> f32 {
    let span = cos_inner - cos_outer;
    if span <= 1e-7 {
        return if cos_a >= cos_outer { 1.0 } else { 0.0 };
    }
    let t = ((cos_a - cos_outer) / span).clamp(0.0, 1.0);
    t * t
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::light::LightKind;

    #[test]
    fn an_area_light_falls_off_with_the_cosine_either_side() {
        let l = Light {
            kind: LightKind::Area {
                position: Vec3::new(0.0, 2.0, 0.0),
                axis: Vec3::Y,
                along: 3.0,
                around: 1.0,
                radius: 0.5,
            },
            color: Vec3::new(1.0, 0.5, 2.0),
            shadows: true,
            range: None,
        };
        // On the axis: (along + around) / (r^2 + radius^2).
        let i = incidence(&l, Vec3::ZERO).unwrap();
        assert!((i.e - l.color * (4.0 / 4.25)).length() < 1e-5, "{:?}", i.e);
        assert!((i.l - Vec3::Y).length() < 1e-6);
        // The same above it: both sides emit.
        let up = incidence(&l, Vec3::new(0.0, 4.0, 0.0)).unwrap();
        assert!((up.e - i.e).length() < 1e-5);
        // At 60 degrees from the axis, along counts half.
        let p = Vec3::new(2.0 * 3f32.sqrt(), 0.0, 0.0);
        let e = incidence(&l, p).unwrap().e.x;
        assert!((e - 2.5 / (16.0 + 0.25)).abs() < 1e-5, "{e}");
        // In the disc's plane only `around` is left; without it, nothing.
        let side = incidence(&l, Vec3::new(3.0, 2.0, 0.0)).unwrap().e.x;
        assert!((side - 1.0 / 9.25).abs() < 1e-5, "{side}");
        let mut flat = l;
        if let LightKind::Area { around, .. } = &mut flat.kind {
            *around = 0.0;
        }
        assert!(incidence(&flat, Vec3::new(3.0, 2.0, 0.0)).is_none());
    }

    #[test]
    fn point_light_follows_inverse_square() {
        let l = Light {
            kind: LightKind::Point {
                position: Vec3::new(0.0, 2.0, 0.0),
                intensity: 8.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        };
        let i = incidence(&l, Vec3::ZERO).unwrap();
        assert!((i.e.x - 2.0).abs() < 1e-6);
        assert!((i.l - Vec3::Y).length() < 1e-6);
        // A range window: (1 - (2/4)^4)^2 at half the range, 0 beyond it.
        let ranged = Light {
            range: Some(4.0),
            ..l
        };
        let w = (1.0f32 - 0.0625).powi(2);
        assert!((incidence(&ranged, Vec3::ZERO).unwrap().e.x - 2.0 * w).abs() < 1e-6);
        assert!(incidence(&ranged, Vec3::new(0.0, -3.0, 0.0)).is_none());
    }

    #[test]
    fn a_light_set_visits_its_mask_in_order() {
        let l = |x: f32| Light {
            kind: LightKind::Point {
                position: Vec3::splat(x),
                intensity: 1.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        };
        let visit = |lights: &[Light], mask: LightMask| {
            let mut seen = Vec::new();
            LightSet { lights, mask }.for_each(|i, light| {
                assert_eq!(*light, lights[i]);
                seen.push(i);
            });
            seen
        };
        let few: Vec<Light> = (0..5).map(|i| l(i as f32)).collect();
        assert_eq!(visit(&few, LightMask::ALL), vec![0, 1, 2, 3, 4]);
        assert_eq!(visit(&few, LightMask::NONE), Vec::<usize>::new());
        let m = LightMask::NONE.with(1).with(3);
        assert_eq!(visit(&few, m), vec![1, 3]);
        assert!(m.has(3) && !m.has(2));
        // Empty: no bit, or bits only past the frame's lights.
        let set = |lights, mask| LightSet { lights, mask };
        assert!(set(&few, LightMask::NONE).is_empty());
        assert!(set(&few, LightMask::NONE.with(7)).is_empty());
        assert!(set(&[], LightMask::ALL).is_empty());
        assert!(!set(&few, m).is_empty());
        // Beyond 63 lights the rest share one bit and are never culled.
        let many: Vec<Light> = (0..70).map(|i| l(i as f32)).collect();
        assert_eq!(visit(&many, LightMask::ALL), (0..70).collect::<Vec<_>>());
        let m = LightMask::NONE.with(2).with(65);
        assert_eq!(
            visit(&many, m),
            [2].into_iter().chain(63..70).collect::<Vec<_>>()
        );
        assert_eq!(visit(&many, LightMask::NONE.with(62)), vec![62]);
        assert_eq!(
            visit(&many[..63], LightMask::ALL),
            (0..63).collect::<Vec<_>>()
        );
    }

    /// Random boxes, point and spot lights with and without ranges: where
    /// `may_reach` says no, no point of the box gets any light; and it
    /// does say no often (the culling is not vacuous).
    #[test]
    fn may_reach_never_culls_a_light_that_reaches() {
        let mut next = crate::testing::xorshift(0x5851_f42d_4c95_7f2d);
        let mut v3 =
            |s: f32| Vec3::new(next() * 2.0 - 1.0, next() * 2.0 - 1.0, next() * 2.0 - 1.0) * s;
        let (mut culled, mut kept) = (0, 0);
        for k in 0..4000 {
            let position = v3(4.0);
            let direction = v3(1.0).normalize_or(Vec3::Y);
            let range = (k % 3 != 0).then(|| 0.2 + v3(1.0).x.abs() * 3.0);
            let outer = 2.0 + 60.0 * v3(1.0).y.abs();
            let kind = if k % 2 == 0 {
                LightKind::Point {
                    position,
                    intensity: 1.0,
                }
            } else {
                LightKind::Spot {
                    position,
                    direction,
                    intensity: 1.0,
                    cos_inner: (outer * 0.5).to_radians().cos(),
                    cos_outer: outer.to_radians().cos(),
                }
            };
            let light = Light {
                kind,
                color: Vec3::ONE,
                shadows: false,
                range,
            };
            let c = v3(3.0);
            let half = v3(1.0).abs() * 0.8;
            let (lo, hi) = (c - half, c + half);
            if may_reach(&light, lo, hi) {
                kept += 1;
                continue;
            }
            culled += 1;
            for _ in 0..200 {
                let t = v3(1.0) * 0.5 + Vec3::splat(0.5);
                let p = lo + (hi - lo) * t;
                let e = incidence(&light, p).map(|i| i.e);
                assert!(
                    e.is_none(),
                    "{light:?} culled for {lo}..{hi} but gives {e:?} at {p}"
                );
            }
            // The corner nearest the light, and the box's points nearest
            // to the spot's axis are among the samples above; the corners
            // too.
            for corner in 0..8 {
                let pick = |b: usize, a: f32, z: f32| if corner >> b & 1 == 0 { a } else { z };
                let p = Vec3::new(
                    pick(0, lo.x, hi.x),
                    pick(1, lo.y, hi.y),
                    pick(2, lo.z, hi.z),
                );
                let e = incidence(&light, p).map(|i| i.e);
                assert!(
                    e.is_none(),
                    "{light:?} culled but gives {e:?} at corner {p}"
                );
            }
        }
        assert!(culled > 800 && kept > 800, "culled {culled}, kept {kept}");
        // Directional lights and unlimited points reach everything.
        let sun = Light {
            kind: LightKind::Directional {
                direction: -Vec3::Y,
                irradiance: 1.0,
                angle: 0.0,
            },
            color: Vec3::ONE,
            shadows: false,
            range: None,
        };
        assert!(may_reach(&sun, Vec3::splat(100.0), Vec3::splat(101.0)));
    }

    #[test]
    fn spot_cone_is_smooth_and_bounded() {
        let (ci, co) = (20f32.to_radians().cos(), 30f32.to_radians().cos());
        assert_eq!(spot_falloff(1.0, ci, co), 1.0);
        assert_eq!(spot_falloff(35f32.to_radians().cos(), ci, co), 0.0);
        let mid = spot_falloff(25f32.to_radians().cos(), ci, co);
        assert!(mid > 0.0 && mid < 1.0);
        assert_eq!(spot_falloff(0.9, 0.5, 0.5), 1.0);
        assert_eq!(spot_falloff(0.4, 0.5, 0.5), 0.0);
    }
}
