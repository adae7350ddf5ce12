//! Animation clips as glTF stores them: per channel, a node's translation,
//! rotation, scale or morph weights as keyframes, sampled STEP, LINEAR
//! (rotations by slerp on the shorter arc) or CUBICSPLINE (Hermite with
//! the file's in- and out-tangents scaled by the key interval; rotations
//! normalized after). Before the first key a channel holds the first
//! value, after the last the last.

use glam::{Quat, Vec4};

/// What a channel drives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ChannelPath {
    /// The node's translation.
    Translation,
    /// The node's rotation.
    Rotation,
    /// The node's scale.
    Scale,
    /// The node's morph target weights.
    Weights,
}

/// How a channel moves between keys (glTF's sampler interpolation).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    /// Each key's value until the next.
    Step,
    /// Linear (rotations: spherical linear).
    Linear,
    /// Cubic Hermite with the file's tangents.
    CubicSpline,
}

/// One animated property of one node.
#[derive(Debug, Clone, PartialEq)]
pub struct Channel {
    /// The node it drives.
    pub node: usize,
    /// What it drives.
    pub path: ChannelPath,
    /// How it moves between keys.
    pub interpolation: Interpolation,
    /// Key times in seconds, increasing.
    pub times: Vec<f32>,
    /// `width` floats per key (three groups of them per key for
    /// CUBICSPLINE: in-tangent, value, out-tangent).
    pub values: Vec<f32>,
    /// Floats per value: 3 (translation, scale), 4 (rotation, x y z w) or
    /// the number of morph targets.
    pub width: usize,
}

/// One glTF animation.
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    /// The file's name for it ("" when it has none).
    pub name: String,
    /// Its channels.
    pub channels: Vec<Channel>,
    /// Seconds: the last key time of any channel.
    pub duration: f32,
}

impl Channel {
    /// Checks the keys: at least one, finite and increasing times, the
    /// right number of finite values.
    pub fn check(&self) -> Result<(), String> {
        if self.times.is_empty() {
            return Err("it has no keys".into());
        }
        if let Some(k) = self.times.windows(2).position(|w| {
            w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater)
                || !w[0].is_finite()
                || !w[1].is_finite()
        }) {
            return Err(format!(
                "its key times are not increasing and finite (key {} at {}, key {} at {})",
                k,
                self.times[k],
                k + 1,
                self.times[k + 1]
            ));
        }
        if !self.times[0].is_finite() {
            return Err("its key times are not finite".into());
        }
        let per_key = match self.interpolation {
            Interpolation::CubicSpline => 3 * self.width,
            _ => self.width,
        };
        if self.width == 0 || self.values.len() != per_key * self.times.len() {
            return Err(format!(
                "it has {} output values for {} keys, {} expected",
                self.values.len(),
                self.times.len(),
                per_key * self.times.len()
            ));
        }
        if self.values.iter().any(|v| !v.is_finite()) {
            return Err("its output values are not finite".into());
        }
        Ok(())
    }

    /// The value of key `k` (for CUBICSPLINE: its value, not a tangent).
    fn key(&self, k: usize) -> &[f32] {
        let w = self.width;
        match self.interpolation {
            Interpolation::CubicSpline => &self.values[(3 * k + 1) * w..(3 * k + 2) * w],
            _ => &self.values[k * w..(k + 1) * w],
        }
    }

    /// The channel's value at time `t` into `out` (`width` floats).
    pub fn sample(&self, t: f32, out: &mut [f32]) {
        let w = self.width;
        let n = self.times.len();
        let last = n - 1;
        let k = self.times.partition_point(|&x| x <= t);
        if k == 0 || n == 1 {
            out[..w].copy_from_slice(self.key(0));
            return;
        }
        if k > last {
            out[..w].copy_from_slice(self.key(last));
            return;
        }
        // times[k - 1] <= t < times[k]
        let (a, b) = (k - 1, k);
        let dt = self.times[b] - self.times[a];
        let s = ((t - self.times[a]) / dt).clamp(0.0, 1.0);
        match self.interpolation {
            Interpolation::Step => out[..w].copy_from_slice(self.key(a)),
            Interpolation::Linear => {
                let (va, vb) = (self.key(a), self.key(b));
                if self.path == ChannelPath::Rotation {
                    let qa = Quat::from_vec4(Vec4::from_slice(va)).normalize();
                    let qb = Quat::from_vec4(Vec4::from_slice(vb)).normalize();
                    let q = slerp(qa, qb, s);
                    out[..4].copy_from_slice(&q.to_array());
                } else {
                    for i in 0..w {
                        out[i] = va[i] + (vb[i] - va[i]) * s;
                    }
                }
            }
            Interpolation::CubicSpline => {
                let v = |k: usize, part: usize| {
                    &self.values[(3 * k + part) * w..(3 * k + part + 1) * w]
                };
                let (p0, m0) = (v(a, 1), v(a, 2));
                let (p1, m1) = (v(b, 1), v(b, 0));
                let (s2, s3) = (s * s, s * s * s);
                let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
                let h10 = s3 - 2.0 * s2 + s;
                let h01 = -2.0 * s3 + 3.0 * s2;
                let h11 = s3 - s2;
                for i in 0..w {
                    out[i] = h00 * p0[i] + h10 * dt * m0[i] + h01 * p1[i] + h11 * dt * m1[i];
                }
                if self.path == ChannelPath::Rotation {
                    let q = Quat::from_slice(&out[..4]);
                    let q = if q.length_squared() > 0.0 {
                        q.normalize()
                    } else {
                        Quat::IDENTITY
                    };
                    out[..4].copy_from_slice(&q.to_array());
                }
            }
        }
    }
}

/// Spherical interpolation on the shorter arc (a and b unit quaternions).
fn slerp(a: Quat, b: Quat, s: f32) -> Quat {
    let mut d = a.dot(b);
    let b = if d < 0.0 {
        d = -d;
        -b
    } else {
        b
    };
    if d > 0.9995 {
        // Nearly parallel: a normalized lerp is exact to float precision.
        return (a * (1.0 - s) + b * s).normalize();
    }
    let theta = d.clamp(-1.0, 1.0).acos();
    let sin = theta.sin();
    a * (((1.0 - s) * theta).sin() / sin) + b * ((s * theta).sin() / sin)
}

impl Clip {
    /// The clip's time for animation time `t` seconds: it loops (a clip
    /// of length 0 stays at 0).
    pub fn local_time(&self, t: f64) -> f32 {
        let d = self.duration as f64;
        if d <= 0.0 || !t.is_finite() {
            return 0.0;
        }
        t.rem_euclid(d) as f32
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn chan(
        path: ChannelPath,
        interpolation: Interpolation,
        times: &[f32],
        values: &[f32],
        width: usize,
    ) -> Channel {
        let c = Channel {
            node: 0,
            path,
            interpolation,
            times: times.to_vec(),
            values: values.to_vec(),
            width,
        };
        c.check().unwrap();
        c
    }

    fn at(c: &Channel, t: f32) -> Vec<f32> {
        let mut out = vec![0.0; c.width];
        c.sample(t, &mut out);
        out
    }

    #[test]
    fn step_and_linear_hold_at_the_ends() {
        let l = chan(
            ChannelPath::Translation,
            Interpolation::Linear,
            &[1.0, 2.0],
            &[0.0, 0.0, 0.0, 2.0, 4.0, 6.0],
            3,
        );
        assert_eq!(at(&l, 0.0), vec![0.0, 0.0, 0.0]);
        assert_eq!(at(&l, 1.25), vec![0.5, 1.0, 1.5]);
        assert_eq!(at(&l, 2.0), vec![2.0, 4.0, 6.0]);
        assert_eq!(at(&l, 9.0), vec![2.0, 4.0, 6.0]);
        let s = Channel {
            interpolation: Interpolation::Step,
            ..l.clone()
        };
        assert_eq!(at(&s, 1.99), vec![0.0, 0.0, 0.0]);
        assert_eq!(at(&s, 2.0), vec![2.0, 4.0, 6.0]);
    }

    #[test]
    fn rotations_slerp_on_the_shorter_arc() {
        let h = std::f32::consts::FRAC_1_SQRT_2;
        // 0 and 90 degrees about Y; the second key written negated.
        let r = chan(
            ChannelPath::Rotation,
            Interpolation::Linear,
            &[0.0, 1.0],
            &[0.0, 0.0, 0.0, 1.0, 0.0, -h, 0.0, -h],
            4,
        );
        let q = Quat::from_slice(&at(&r, 0.5));
        let want = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
        assert!(q.dot(want).abs() > 1.0 - 1e-6, "{q}");
        // Constant angular speed: a third of the way is 30 degrees.
        let q = Quat::from_slice(&at(&r, 1.0 / 3.0));
        let want = Quat::from_rotation_y(std::f32::consts::FRAC_PI_6);
        assert!(q.dot(want).abs() > 1.0 - 1e-6, "{q}");
    }

    #[test]
    fn cubic_splines_pass_through_keys_and_follow_their_tangents() {
        // Scalar weights: keys 0 -> 1 over 2 s with out-tangent 1/s at the
        // first key and in-tangent 0 at the second; Hermite by hand.
        let c = chan(
            ChannelPath::Weights,
            Interpolation::CubicSpline,
            &[0.0, 2.0],
            &[9.0, 0.0, 1.0, 0.0, 1.0, 9.0],
            1,
        );
        assert_eq!(at(&c, 0.0), vec![0.0]);
        assert_eq!(at(&c, 2.0), vec![1.0]);
        let s: f32 = 0.25;
        let want = (-2.0 * s.powi(3) + 3.0 * s * s) + (s.powi(3) - 2.0 * s * s + s) * 2.0 * 1.0;
        assert!((at(&c, 0.5)[0] - want).abs() < 1e-6);
        // Tangents of the end keys outside the interval are not used.
        assert!(at(&c, 3.0)[0] == 1.0);
    }

    #[test]
    fn bad_keys_are_refused() {
        let mut c = Channel {
            node: 0,
            path: ChannelPath::Scale,
            interpolation: Interpolation::Linear,
            times: vec![0.0, 0.0],
            values: vec![1.0; 6],
            width: 3,
        };
        assert!(c.check().unwrap_err().contains("increasing"));
        c.times = vec![0.0, 1.0];
        c.values.pop();
        assert!(c.check().unwrap_err().contains("5 output values"));
        c.times = vec![];
        assert!(c.check().is_err());
    }

    #[test]
    fn clips_loop() {
        let c = Clip {
            name: "w".into(),
            channels: vec![],
            duration: 2.0,
        };
        assert_eq!(c.local_time(0.5), 0.5);
        assert_eq!(c.local_time(2.5), 0.5);
        let z = Clip { duration: 0.0, ..c };
        assert_eq!(z.local_time(3.0), 0.0);
    }
}
