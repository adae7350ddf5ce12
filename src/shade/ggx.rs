//! The GGX microfacet lobe's D times Smith's visibility, and the smallest
//! alpha: the math the pbr materials' lights (`pbr`) and the surfaces a
//! traced reflection meets (`env::reflect`) share.

use std::f32::consts::PI;

use crate::simd::{Lane, V3};

/// Smallest alpha: a perfect mirror would make D a delta that point lights
/// never hit; this keeps a tiny, finite highlight.
pub const MIN_ALPHA: f32 = 2e-3;

/// GGX's D times the separable Smith visibility for n.l = `ndl` > 0 and
/// half vector `h`, per lane.
#[inline(always)]
pub fn d_vis<L: Lane>(n: V3<L>, v: V3<L>, h: V3<L>, ndl: L, a2: L) -> L {
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
