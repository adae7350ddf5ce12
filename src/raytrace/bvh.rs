//! A bounding volume hierarchy over one mesh's triangles, built once in
//! object space with the surface area heuristic (binned, 16 bins per axis),
//! answering "is anything hit between t_min and t_max" (any-hit) and
//! "where is the nearest hit" along a ray.
//!
//! Nodes are flattened depth-first: an interior node's left child follows it
//! and `index` names its right child; a leaf's `index` is its first triangle
//! in the reordered triangle list.

use glam::{Vec3, Vec3A};

const BINS: usize = 16;
const MAX_LEAF: usize = 8;
/// Cost of one triangle test relative to one node traversal step.
const TRI_COST: f32 = 1.0;
const NODE_COST: f32 = 1.0;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: Vec3A,
    hi: Vec3A,
    /// Interior: right child; leaf: first triangle.
    index: u32,
    /// 0 for an interior node; the leaf's triangle count otherwise.
    count: u32,
}

/// A triangle ready for the Moller-Trumbore test: a vertex and two edges.
#[derive(Debug, Clone, Copy)]
struct Triangle {
    v0: Vec3A,
    e1: Vec3A,
    e2: Vec3A,
}

#[derive(Debug, Clone, Default)]
pub struct Bvh {
    nodes: Vec<Node>,
    tris: Vec<Triangle>,
    /// Index into the mesh's triangle list, per reordered triangle.
    prim: Vec<u32>,
}

/// A hit: ray parameter and the mesh triangle index.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    pub t: f32,
    pub prim: u32,
}

#[derive(Clone, Copy)]
struct Aabb {
    lo: Vec3A,
    hi: Vec3A,
}

impl Aabb {
    const EMPTY: Aabb = Aabb {
        lo: Vec3A::splat(f32::INFINITY),
        hi: Vec3A::splat(f32::NEG_INFINITY),
    };
    fn grow(&mut self, o: &Aabb) {
        self.lo = self.lo.min(o.lo);
        self.hi = self.hi.max(o.hi);
    }
    fn grow_point(&mut self, p: Vec3A) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
    }
    fn half_area(&self) -> f32 {
        let d = (self.hi - self.lo).max(Vec3A::ZERO);
        d.x * d.y + d.y * d.z + d.z * d.x
    }
}

impl Bvh {
    /// Builds over `triangles` (indices into `positions`). Degenerate and
    /// non-finite triangles are left out: they cannot be hit.
    pub fn build(positions: &[Vec3], triangles: &[[u32; 3]]) -> Bvh {
        let mut refs: Vec<(u32, Aabb, Vec3A)> = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            let p = t.map(|k| Vec3A::from(positions[k as usize]));
            if !(p[0].is_finite() && p[1].is_finite() && p[2].is_finite()) {
                continue;
            }
            if (p[1] - p[0]).cross(p[2] - p[0]).length_squared() == 0.0 {
                continue;
            }
            let mut b = Aabb::EMPTY;
            for q in p {
                b.grow_point(q);
            }
            refs.push((i as u32, b, (b.lo + b.hi) * 0.5));
        }
        let mut bvh = Bvh::default();
        if refs.is_empty() {
            return bvh;
        }
        bvh.nodes.reserve(refs.len());
        bvh.build_node(&mut refs, 0);
        bvh.tris = bvh
            .prim
            .iter()
            .map(|&i| {
                let p = triangles[i as usize].map(|k| Vec3A::from(positions[k as usize]));
                Triangle {
                    v0: p[0],
                    e1: p[1] - p[0],
                    e2: p[2] - p[0],
                }
            })
            .collect();
        bvh
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    /// The same tree over the same triangles with their vertices moved to
    /// `positions` (a posed mesh of unchanged topology): triangles
    /// re-read, every node's box recomputed from its children. Linear in
    /// the triangles, against a full build's n log n sorting; the tree
    /// keeps the split of the pose it was built for, so rays visit more
    /// nodes the further the pose has moved, but every answer is exact.
    /// Triangles left out of the build (degenerate there) stay out.
    pub fn refit(&self, positions: &[Vec3], triangles: &[[u32; 3]]) -> Bvh {
        let vertex = |k: u32| Vec3A::from(positions.get(k as usize).copied().unwrap_or(Vec3::ZERO));
        let tris: Vec<Triangle> = self
            .prim
            .iter()
            .map(|&i| {
                let p = triangles
                    .get(i as usize)
                    .map_or([Vec3A::ZERO; 3], |t| t.map(vertex));
                Triangle {
                    v0: p[0],
                    e1: p[1] - p[0],
                    e2: p[2] - p[0],
                }
            })
            .collect();
        let mut nodes = self.nodes.clone();
        // Depth-first order: children follow their parent, so a reverse
        // pass sees both children before the parent.
        for i in (0..nodes.len()).rev() {
            let n = nodes[i];
            let mut b = Aabb::EMPTY;
            if n.count > 0 {
                for t in &tris[n.index as usize..(n.index + n.count) as usize] {
                    b.grow_point(t.v0);
                    b.grow_point(t.v0 + t.e1);
                    b.grow_point(t.v0 + t.e2);
                }
            } else {
                for c in [i + 1, n.index as usize] {
                    b.grow(&Aabb {
                        lo: nodes[c].lo,
                        hi: nodes[c].hi,
                    });
                }
            }
            nodes[i].lo = b.lo;
            nodes[i].hi = b.hi;
        }
        Bvh {
            nodes,
            tris,
            prim: self.prim.clone(),
        }
    }

    /// Appends the node for `refs` (and its subtree); returns its index.
    fn build_node(&mut self, refs: &mut [(u32, Aabb, Vec3A)], depth: u32) -> usize {
        let mut bounds = Aabb::EMPTY;
        let mut cbounds = Aabb::EMPTY;
        for r in refs.iter() {
            bounds.grow(&r.1);
            cbounds.grow_point(r.2);
        }
        let me = self.nodes.len();
        self.nodes.push(Node {
            lo: bounds.lo,
            hi: bounds.hi,
            index: 0,
            count: 0,
        });
        let n = refs.len();
        let split = if n <= 2 || depth >= 60 {
            None
        } else {
            best_split(refs, &bounds, &cbounds)
        };
        let leaf_cost = TRI_COST * n as f32;
        let split = match split {
            Some((axis, pos, cost)) if cost < leaf_cost || n > MAX_LEAF => Some((axis, pos)),
            _ if n > MAX_LEAF => {
                // All centroids in one bin: split by count along the widest
                // centroid axis.
                let ext = cbounds.hi - cbounds.lo;
                let axis = if ext.x >= ext.y && ext.x >= ext.z {
                    0
                } else if ext.y >= ext.z {
                    1
                } else {
                    2
                };
                refs.sort_by(|a, b| a.2[axis].total_cmp(&b.2[axis]).then(a.0.cmp(&b.0)));
                Some((axis, f32::NAN))
            }
            _ => None,
        };
        let Some((axis, pos)) = split else {
            self.nodes[me].index = self.prim.len() as u32;
            self.nodes[me].count = n as u32;
            self.prim.extend(refs.iter().map(|r| r.0));
            return me;
        };
        let mid = if pos.is_nan() {
            n / 2
        } else {
            let mut i = 0;
            for j in 0..n {
                if refs[j].2[axis] < pos {
                    refs.swap(i, j);
                    i += 1;
                }
            }
            if i == 0 || i == n { n / 2 } else { i }
        };
        let (left, right) = refs.split_at_mut(mid);
        self.build_node(left, depth + 1);
        let r = self.build_node(right, depth + 1);
        self.nodes[me].index = r as u32;
        me
    }

    /// Any hit with t in (t_min, t_max) along `o + t d` (d need not be unit).
    pub fn occluded(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> bool {
        self.traverse(o, d, t_min, t_max, true, |_| true).is_some()
    }

    /// The nearest hit with t in (t_min, t_max).
    pub fn nearest(&self, o: Vec3, d: Vec3, t_min: f32, t_max: f32) -> Option<Hit> {
        self.traverse(o, d, t_min, t_max, false, |_| true)
    }

    /// `occluded`, counting only the hits `keep` keeps (a ray goes on
    /// through the others: the holes of a cut-out leaf).
    pub fn occluded_where(
        &self,
        (o, d): (Vec3, Vec3),
        (t_min, t_max): (f32, f32),
        keep: impl Fn(Hit) -> bool,
    ) -> bool {
        self.traverse(o, d, t_min, t_max, true, keep).is_some()
    }

    /// `nearest`, counting only the hits `keep` keeps.
    pub fn nearest_where(
        &self,
        (o, d): (Vec3, Vec3),
        (t_min, t_max): (f32, f32),
        keep: impl Fn(Hit) -> bool,
    ) -> Option<Hit> {
        self.traverse(o, d, t_min, t_max, false, keep)
    }

    #[inline]
    fn traverse(
        &self,
        o: Vec3,
        d: Vec3,
        t_min: f32,
        t_max: f32,
        any: bool,
        keep: impl Fn(Hit) -> bool,
    ) -> Option<Hit> {
        if self.nodes.is_empty() {
            return None;
        }
        let o = Vec3A::from(o);
        let d = Vec3A::from(d);
        let inv = d.recip();
        let mut t_max = t_max;
        let mut best = None;
        let mut stack = [0u32; 64];
        let mut sp = 0usize;
        let mut node = 0usize;
        loop {
            let n = &self.nodes[node];
            if slab(n, o, inv, t_min, t_max) {
                if n.count == 0 {
                    // Interior: visit the left child now, the right later.
                    if sp < stack.len() {
                        stack[sp] = n.index;
                        sp += 1;
                    }
                    node += 1;
                    continue;
                }
                let first = n.index as usize;
                for k in first..first + n.count as usize {
                    if let Some(t) = intersect(&self.tris[k], o, d, t_min, t_max) {
                        let hit = Hit {
                            t,
                            prim: self.prim[k],
                        };
                        if !keep(hit) {
                            continue;
                        }
                        best = Some(hit);
                        if any {
                            return best;
                        }
                        t_max = t;
                    }
                }
            }
            if sp == 0 {
                return best;
            }
            sp -= 1;
            node = stack[sp] as usize;
        }
    }
}

/// The cheapest SAH split over all three axes: (axis, plane, cost).
fn best_split(
    refs: &[(u32, Aabb, Vec3A)],
    bounds: &Aabb,
    cbounds: &Aabb,
) -> Option<(usize, f32, f32)> {
    let inv_area = 1.0 / bounds.half_area().max(f32::MIN_POSITIVE);
    let mut best: Option<(usize, f32, f32)> = None;
    for axis in 0..3 {
        let (lo, hi) = (cbounds.lo[axis], cbounds.hi[axis]);
        if hi - lo <= 0.0 {
            continue;
        }
        let scale = BINS as f32 / (hi - lo);
        let mut bins = [(Aabb::EMPTY, 0u32); BINS];
        for r in refs {
            let b = (((r.2[axis] - lo) * scale) as usize).min(BINS - 1);
            bins[b].0.grow(&r.1);
            bins[b].1 += 1;
        }
        // Areas and counts to the right of each plane.
        let mut right = [(0.0f32, 0u32); BINS];
        let mut acc = Aabb::EMPTY;
        let mut cnt = 0;
        for i in (1..BINS).rev() {
            acc.grow(&bins[i].0);
            cnt += bins[i].1;
            right[i] = (acc.half_area(), cnt);
        }
        let mut acc = Aabb::EMPTY;
        let mut cnt = 0;
        for i in 0..BINS - 1 {
            acc.grow(&bins[i].0);
            cnt += bins[i].1;
            let (ra, rc) = right[i + 1];
            if cnt == 0 || rc == 0 {
                continue;
            }
            let cost =
                NODE_COST + TRI_COST * (acc.half_area() * cnt as f32 + ra * rc as f32) * inv_area;
            if best.is_none_or(|b| cost < b.2) {
                best = Some((axis, lo + (i + 1) as f32 / scale, cost));
            }
        }
    }
    best
}

#[inline(always)]
fn slab(n: &Node, o: Vec3A, inv: Vec3A, t_min: f32, t_max: f32) -> bool {
    let t0 = (n.lo - o) * inv;
    let t1 = (n.hi - o) * inv;
    // NaN (0 * inf on a slab's plane) loses to the other operand in min/max.
    let near = t0.min(t1).max_element().max(t_min);
    let far = t0.max(t1).min_element().min(t_max);
    near <= far
}

/// Moller-Trumbore, two-sided.
#[inline(always)]
fn intersect(t: &Triangle, o: Vec3A, d: Vec3A, t_min: f32, t_max: f32) -> Option<f32> {
    let p = d.cross(t.e2);
    let det = t.e1.dot(p);
    if det == 0.0 {
        return None;
    }
    let inv = 1.0 / det;
    let s = o - t.v0;
    let u = s.dot(p) * inv;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(t.e1);
    let v = d.dot(q) * inv;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = t.e2.dot(q) * inv;
    (t > t_min && t < t_max).then_some(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::procedural;

    fn brute(pos: &[Vec3], tris: &[[u32; 3]], o: Vec3, d: Vec3) -> Option<f32> {
        let mut best: Option<f32> = None;
        for t in tris {
            let p = t.map(|k| Vec3A::from(pos[k as usize]));
            let tri = Triangle {
                v0: p[0],
                e1: p[1] - p[0],
                e2: p[2] - p[0],
            };
            if let Some(h) = intersect(&tri, o.into(), d.into(), 0.0, f32::INFINITY) {
                best = Some(best.map_or(h, |b: f32| b.min(h)));
            }
        }
        best
    }

    #[test]
    fn agrees_with_brute_force_on_a_torus() {
        let b = procedural::torus(1.0, 0.35, 48, 24);
        let pos: Vec<Vec3> = b.v.iter().map(|&p| Vec3::from(p)).collect();
        // OBJ-style 1-based indices.
        let tris: Vec<[u32; 3]> = b.f.iter().map(|f| f.map(|k| k as u32 - 1)).collect();
        let bvh = Bvh::build(&pos, &tris);
        // Deterministic rays from a ring of origins towards jittered targets.
        let mut misses = 0;
        for i in 0..400 {
            let a = i as f32 * 0.7;
            let o = Vec3::new(3.0 * a.cos(), 1.5 * (a * 1.3).sin(), 3.0 * a.sin());
            let target = Vec3::new((a * 2.1).sin(), (a * 0.37).cos() * 0.3, (a * 1.7).cos()) * 1.6;
            let d = target - o;
            let want = brute(&pos, &tris, o, d);
            let got = bvh.nearest(o, d, 0.0, f32::INFINITY).map(|h| h.t);
            assert_eq!(want.is_some(), got.is_some(), "ray {i}");
            if let (Some(w), Some(g)) = (want, got) {
                assert!((w - g).abs() < 1e-5, "ray {i}: {w} vs {g}");
            } else {
                misses += 1;
            }
            assert_eq!(bvh.occluded(o, d, 0.0, f32::INFINITY), want.is_some());
            if let Some(w) = want {
                // Bounded rays stop short of the hit.
                assert!(!bvh.occluded(o, d, 0.0, w * 0.999));
            }
        }
        assert!(
            misses > 20 && misses < 380,
            "a mix of hits and misses: {misses}"
        );
    }
}
