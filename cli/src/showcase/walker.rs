//! A walking figure as a binary glTF, made by code: one skinned mesh
//! (tubes for the legs, arms and torso, a sphere for the head, boxes for
//! the feet; vertex colours for shirt, trousers, skin and shoes) on an
//! eleven-joint skeleton, with one clip, "Walk": a one-second walk cycle
//! in place, sampled every 1/16 s, LINEAR. Vertices near the knees,
//! elbows, hips and neck blend two joints, so the joints bend smoothly.

use std::f32::consts::{PI, TAU};

use glam::{Mat4, Quat, Vec3};
use serde_json::{Value, json};

/// The joints: name, parent, translation from the parent at rest.
const JOINTS: [(&str, Option<usize>, [f32; 3]); 11] = [
    ("hips", None, [0.0, 0.95, 0.0]),
    ("spine", Some(0), [0.0, 0.1, 0.0]),
    ("head", Some(1), [0.0, 0.58, 0.0]),
    ("thigh.L", Some(0), [0.1, -0.05, 0.0]),
    ("shin.L", Some(3), [0.0, -0.45, 0.0]),
    ("thigh.R", Some(0), [-0.1, -0.05, 0.0]),
    ("shin.R", Some(5), [0.0, -0.45, 0.0]),
    ("arm.L", Some(1), [0.245, 0.46, 0.0]),
    ("forearm.L", Some(7), [0.0, -0.29, 0.0]),
    ("arm.R", Some(1), [-0.245, 0.46, 0.0]),
    ("forearm.R", Some(9), [0.0, -0.29, 0.0]),
];

const SHIRT: [f32; 4] = [0.16, 0.33, 0.62, 1.0];
const TROUSERS: [f32; 4] = [0.12, 0.12, 0.14, 1.0];
const SKIN: [f32; 4] = [0.80, 0.55, 0.42, 1.0];
const SHOES: [f32; 4] = [0.35, 0.12, 0.08, 1.0];

/// Sides of every tube.
const SIDES: usize = 16;

/// Bind-pose world position of each joint.
fn joint_positions() -> Vec<Vec3> {
    let mut out: Vec<Vec3> = Vec::new();
    for (_, parent, t) in JOINTS {
        let base = parent.map_or(Vec3::ZERO, |p| out[p]);
        out.push(base + Vec3::from(t));
    }
    out
}

#[derive(Default)]
struct Skinned {
    positions: Vec<f32>,
    normals: Vec<f32>,
    colors: Vec<f32>,
    joints: Vec<u8>,
    weights: Vec<f32>,
    indices: Vec<u16>,
}

impl Skinned {
    fn vertex(&mut self, p: Vec3, n: Vec3, color: [f32; 4], influences: &[(u8, f32)]) -> u16 {
        let i = (self.positions.len() / 3) as u16;
        self.positions.extend(p.to_array());
        self.normals.extend(n.normalize().to_array());
        self.colors.extend(color);
        let mut j = [0u8; 4];
        let mut w = [0.0f32; 4];
        for (k, (a, b)) in influences.iter().take(4).enumerate() {
            j[k] = *a;
            w[k] = *b;
        }
        self.joints.extend(j);
        self.weights.extend(w);
        i
    }

    /// A tube along -Y from `top` to `bottom` (elliptic section rx, rz),
    /// capped, weighted per ring by `weights(y)`.
    fn tube(
        &mut self,
        (top, bottom): (Vec3, Vec3),
        (rx, rz): (f32, f32),
        rings: usize,
        color: [f32; 4],
        weights: impl Fn(f32) -> Vec<(u8, f32)>,
    ) {
        let first = (self.positions.len() / 3) as u16;
        for r in 0..=rings {
            let f = r as f32 / rings as f32;
            let c = top.lerp(bottom, f);
            let w = weights(c.y);
            for s in 0..SIDES {
                let a = s as f32 / SIDES as f32 * TAU;
                let (sin, cos) = a.sin_cos();
                let p = c + Vec3::new(rx * sin, 0.0, rz * cos);
                let n = Vec3::new(sin / rx, 0.0, cos / rz);
                self.vertex(p, n, color, &w);
            }
        }
        for r in 0..rings as u16 {
            for s in 0..SIDES as u16 {
                let s1 = (s + 1) % SIDES as u16;
                let a = first + r * SIDES as u16 + s;
                let b = first + r * SIDES as u16 + s1;
                let c = a + SIDES as u16;
                let d = b + SIDES as u16;
                self.indices.extend([a, c, b, b, c, d]);
            }
        }
        // Caps: a centre vertex each, fanned to its ring.
        for (centre, n) in [(top, Vec3::Y), (bottom, -Vec3::Y)] {
            let w = weights(centre.y);
            let mid = self.vertex(centre, n, color, &w);
            let mut rim = Vec::new();
            for s in 0..SIDES {
                let a = s as f32 / SIDES as f32 * TAU;
                let p = centre + Vec3::new(rx * a.sin(), 0.0, rz * a.cos());
                rim.push(self.vertex(p, n, color, &w));
            }
            for s in 0..SIDES {
                let (a, b) = (rim[s], rim[(s + 1) % SIDES]);
                if n.y > 0.0 {
                    self.indices.extend([mid, a, b]);
                } else {
                    self.indices.extend([mid, b, a]);
                }
            }
        }
    }

    /// A UV sphere, one joint.
    fn sphere(&mut self, c: Vec3, r: f32, color: [f32; 4], joint: u8) {
        let (cols, rows) = (20usize, 12usize);
        let first = (self.positions.len() / 3) as u16;
        for j in 0..=rows {
            let v = j as f32 / rows as f32 * PI;
            for i in 0..=cols {
                let u = i as f32 / cols as f32 * TAU;
                let n = Vec3::new(v.sin() * u.sin(), v.cos(), v.sin() * u.cos());
                self.vertex(c + n * r, n, color, &[(joint, 1.0)]);
            }
        }
        let w = cols as u16 + 1;
        for j in 0..rows as u16 {
            for i in 0..cols as u16 {
                let a = first + j * w + i;
                let (b, c, d) = (a + 1, a + w, a + w + 1);
                self.indices.extend([a, c, b, b, c, d]);
            }
        }
    }

    /// A box from `lo` to `hi`, one joint, flat faces.
    fn block(&mut self, lo: Vec3, hi: Vec3, color: [f32; 4], joint: u8) {
        let corner = |k: usize| {
            Vec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        };
        // Per face: normal and corners counter-clockwise from outside.
        let faces = [
            (-Vec3::X, [0, 4, 6, 2]),
            (Vec3::X, [1, 3, 7, 5]),
            (-Vec3::Y, [0, 1, 5, 4]),
            (Vec3::Y, [2, 6, 7, 3]),
            (-Vec3::Z, [0, 2, 3, 1]),
            (Vec3::Z, [4, 5, 7, 6]),
        ];
        for (n, q) in faces {
            let v = q.map(|k| self.vertex(corner(k), n, color, &[(joint, 1.0)]));
            self.indices.extend([v[0], v[1], v[2], v[0], v[2], v[3]]);
        }
    }
}

/// Two joints blended linearly across `y` from `lo` (all `below`) to `hi`
/// (all `above`).
fn blend(y: f32, lo: f32, hi: f32, below: u8, above: u8) -> Vec<(u8, f32)> {
    let t = ((y - lo) / (hi - lo)).clamp(0.0, 1.0);
    match t {
        0.0 => vec![(below, 1.0)],
        1.0 => vec![(above, 1.0)],
        t => vec![(below, 1.0 - t), (above, t)],
    }
}

fn mesh() -> Skinned {
    let j = joint_positions();
    let mut m = Skinned::default();
    // Torso: hips joint below the waist, spine above.
    let waist = j[1].y;
    m.tube(
        (
            Vec3::new(0.0, j[7].y + 0.06, 0.0),
            Vec3::new(0.0, j[3].y - 0.03, 0.0),
        ),
        (0.17, 0.11),
        10,
        SHIRT,
        |y| blend(y, waist - 0.08, waist + 0.08, 0, 1),
    );
    // Neck and head.
    m.tube(
        (
            Vec3::new(0.0, j[2].y + 0.02, 0.0),
            Vec3::new(0.0, j[7].y + 0.02, 0.0),
        ),
        (0.05, 0.05),
        3,
        SKIN,
        |y| blend(y, j[2].y - 0.04, j[2].y + 0.01, 1, 2),
    );
    m.sphere(j[2] + Vec3::new(0.0, 0.11, 0.01), 0.115, SKIN, 2);
    for (thigh, shin) in [(3u8, 4u8), (5, 6)] {
        let (hip, knee) = (j[thigh as usize], j[shin as usize]);
        let ankle = knee - Vec3::new(0.0, 0.44, 0.0);
        m.tube(
            (hip + Vec3::Y * 0.04, ankle),
            (0.075, 0.075),
            12,
            TROUSERS,
            |y| {
                if y > hip.y - 0.03 {
                    blend(y, hip.y - 0.03, hip.y + 0.04, thigh, 0)
                } else {
                    blend(y, knee.y - 0.06, knee.y + 0.06, shin, thigh)
                }
            },
        );
        m.block(
            Vec3::new(ankle.x - 0.055, 0.0, -0.06),
            Vec3::new(ankle.x + 0.055, 0.07, 0.17),
            SHOES,
            shin,
        );
    }
    for (arm, fore) in [(7u8, 8u8), (9, 10)] {
        let (shoulder, elbow) = (j[arm as usize], j[fore as usize]);
        let wrist = elbow - Vec3::new(0.0, 0.26, 0.0);
        m.tube(
            (shoulder + Vec3::Y * 0.03, wrist),
            (0.05, 0.05),
            8,
            SHIRT,
            |y| blend(y, elbow.y - 0.05, elbow.y + 0.05, fore, arm),
        );
        m.sphere(wrist - Vec3::Y * 0.05, 0.05, SKIN, fore);
    }
    m
}

/// Per joint, its local rotation at phase `p` (0..1 of the cycle).
fn rotation(joint: usize, p: f32) -> Quat {
    let a = p * TAU;
    let swing = a.sin();
    let x = |r: f32| Quat::from_rotation_x(r);
    match joint {
        0 => Quat::from_rotation_y(0.08 * swing),
        1 => Quat::from_rotation_y(-0.12 * swing) * x(0.05),
        2 => Quat::from_rotation_y(0.05 * swing),
        // Thighs swing forward (toward +Z) with negative x rotations.
        3 => x(-0.42 * swing),
        5 => x(0.42 * swing),
        // Knees bend while the leg swings forward.
        4 => x(0.08 + 0.75 * a.cos().max(0.0).powf(1.5)),
        6 => x(0.08 + 0.75 * (-a.cos()).max(0.0).powf(1.5)),
        // Arms swing against the legs, elbows slightly bent.
        7 => x(0.35 * swing) * Quat::from_rotation_z(0.08),
        9 => x(-0.35 * swing) * Quat::from_rotation_z(-0.08),
        8 => x(-0.3 - 0.15 * (-swing).max(0.0)),
        10 => x(-0.3 - 0.15 * swing.max(0.0)),
        _ => Quat::IDENTITY,
    }
}

/// Keys of the cycle: 1/16 s apart over one second.
const KEYS: usize = 17;

/// The walker as `.glb` bytes.
pub fn walker_glb() -> Vec<u8> {
    let m = mesh();
    let mut blob: Vec<u8> = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut push = |bytes: Vec<u8>, acc: Value| -> usize {
        while !blob.len().is_multiple_of(4) {
            blob.push(0);
        }
        views.push(json!({"buffer": 0, "byteOffset": blob.len(), "byteLength": bytes.len()}));
        blob.extend_from_slice(&bytes);
        let mut acc = acc;
        acc["bufferView"] = json!(views.len() - 1);
        accessors.push(acc);
        accessors.len() - 1
    };
    let f32s = |v: &[f32]| -> Vec<u8> { v.iter().flat_map(|x| x.to_le_bytes()).collect() };
    let n = m.positions.len() / 3;
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    for p in m.positions.chunks(3) {
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    let pos = push(
        f32s(&m.positions),
        json!({"componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi}),
    );
    let nrm = push(
        f32s(&m.normals),
        json!({"componentType": 5126, "count": n, "type": "VEC3"}),
    );
    let col = push(
        f32s(&m.colors),
        json!({"componentType": 5126, "count": n, "type": "VEC4"}),
    );
    let jnt = push(
        m.joints.clone(),
        json!({"componentType": 5121, "count": n, "type": "VEC4"}),
    );
    let wgt = push(
        f32s(&m.weights),
        json!({"componentType": 5126, "count": n, "type": "VEC4"}),
    );
    let idx_bytes: Vec<u8> = m.indices.iter().flat_map(|i| i.to_le_bytes()).collect();
    let idx = push(
        idx_bytes,
        json!({"componentType": 5123, "count": m.indices.len(), "type": "SCALAR"}),
    );
    let rest = joint_positions();
    let ibm: Vec<f32> = rest
        .iter()
        .flat_map(|p| Mat4::from_translation(-*p).to_cols_array())
        .collect();
    let ibm = push(
        f32s(&ibm),
        json!({"componentType": 5126, "count": JOINTS.len(), "type": "MAT4"}),
    );
    let times: Vec<f32> = (0..KEYS).map(|k| k as f32 / (KEYS - 1) as f32).collect();
    let input = push(
        f32s(&times),
        json!({"componentType": 5126, "count": KEYS, "type": "SCALAR", "min": [0.0], "max": [1.0]}),
    );
    let mut samplers = Vec::new();
    let mut channels = Vec::new();
    for joint in 0..JOINTS.len() {
        let q: Vec<f32> = times
            .iter()
            .flat_map(|&t| rotation(joint, t).normalize().to_array())
            .collect();
        let out = push(
            f32s(&q),
            json!({"componentType": 5126, "count": KEYS, "type": "VEC4"}),
        );
        samplers.push(json!({"input": input, "output": out, "interpolation": "LINEAR"}));
        channels.push(
            json!({"sampler": samplers.len() - 1, "target": {"node": joint, "path": "rotation"}}),
        );
    }
    // The hips bob twice a cycle, highest mid-stride.
    let bob: Vec<f32> = times
        .iter()
        .flat_map(|&t| [0.0, JOINTS[0].2[1] + 0.025 * (2.0 * TAU * t).cos(), 0.0])
        .collect();
    let out = push(
        f32s(&bob),
        json!({"componentType": 5126, "count": KEYS, "type": "VEC3"}),
    );
    samplers.push(json!({"input": input, "output": out, "interpolation": "LINEAR"}));
    channels
        .push(json!({"sampler": samplers.len() - 1, "target": {"node": 0, "path": "translation"}}));

    let mut nodes = joint_nodes();
    nodes.push(json!({"name": "walker", "mesh": 0, "skin": 0}));
    let doc = json!({
        "asset": {"version": "2.0", "generator": "softraster generate-assets"},
        "scene": 0,
        "scenes": [{"nodes": [0, JOINTS.len()]}],
        "nodes": nodes,
        "skins": [{"joints": (0..JOINTS.len()).collect::<Vec<_>>(), "inverseBindMatrices": ibm, "skeleton": 0}],
        "materials": [{"name": "walker", "pbrMetallicRoughness": {"baseColorFactor": [1.0, 1.0, 1.0, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.65}}],
        "meshes": [{"name": "walker", "primitives": [{
            "attributes": {"POSITION": pos, "NORMAL": nrm, "COLOR_0": col, "JOINTS_0": jnt, "WEIGHTS_0": wgt},
            "indices": idx, "material": 0}]}],
        "animations": [{"name": "Walk", "samplers": samplers, "channels": channels}],
        "buffers": [{"byteLength": blob.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    glb(&doc, blob)
}

/// The skeleton's nodes: each joint with its rest translation and its
/// children.
fn joint_nodes() -> Vec<Value> {
    JOINTS
        .iter()
        .enumerate()
        .map(|(i, (name, _, t))| {
            let children: Vec<usize> = JOINTS
                .iter()
                .enumerate()
                .filter(|(_, (_, p, _))| *p == Some(i))
                .map(|(k, _)| k)
                .collect();
            let mut node = json!({"name": name, "translation": t});
            if !children.is_empty() {
                node["children"] = json!(children);
            }
            node
        })
        .collect()
}

/// A binary glTF of `doc` and its buffer `blob`.
fn glb(doc: &Value, mut blob: Vec<u8>) -> Vec<u8> {
    let mut json_bytes = serde_json::to_vec(doc).unwrap_or_default();
    while !json_bytes.len().is_multiple_of(4) {
        json_bytes.push(b' ');
    }
    while !blob.len().is_multiple_of(4) {
        blob.push(0);
    }
    let total = 12 + 8 + json_bytes.len() + 8 + blob.len();
    let mut out = Vec::with_capacity(total);
    out.extend(b"glTF");
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json_bytes.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(&json_bytes);
    out.extend((blob.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(&blob);
    out
}
