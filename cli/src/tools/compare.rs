//! Image comparison: golden-frame checks for CI and softraster's own golden
//! tests. Four metrics, each with a per-pixel error map:
//!
//! - `flip` (default): NVIDIA's FLIP (LDR), through the nv-flip crate, at
//!   67 pixels per degree (a 0.7 m wide 4K monitor seen from 0.7 m). The
//!   value is the mean FLIP error in [0, 1]; pass when <= threshold.
//! - `ssim`: structural similarity of the luma (Rec. 709 weights on the
//!   encoded values), 11x11 Gaussian window with sigma 1.5, the usual
//!   constants; mean over pixels; pass when >= threshold.
//! - `psnr`: 10 log10(1 / MSE) over the RGB channels in [0, 1], capped at
//!   100 dB for identical images; pass when >= threshold.
//! - `mae`: mean absolute difference over the RGB channels, as a fraction
//!   of full scale; pass when <= threshold.
//!
//! RGBA images are compared composited over black and over white; the worse
//! of the two counts, so a difference in alpha alone shows.
//!
//! Two directories are compared file by file, paired by name (image files
//! only: png, jpg, jpeg, tga). A file present on one side only fails.

use std::path::{Path, PathBuf};

use rayon::prelude::*;

use softraster::error::Error;
use softraster::output::{Image8, png};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Metric {
    Flip,
    Ssim,
    Psnr,
    Mae,
}

impl Metric {
    pub fn parse(s: &str) -> Option<Metric> {
        Some(match s {
            "flip" => Metric::Flip,
            "ssim" => Metric::Ssim,
            "psnr" => Metric::Psnr,
            "mae" => Metric::Mae,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Metric::Flip => "flip",
            Metric::Ssim => "ssim",
            Metric::Psnr => "psnr",
            Metric::Mae => "mae",
        }
    }

    /// flip 0.05 (mean error), ssim 0.98, psnr 40 dB, mae 0.01 (of full
    /// scale).
    pub fn default_threshold(self) -> f64 {
        match self {
            Metric::Flip => 0.05,
            Metric::Ssim => 0.98,
            Metric::Psnr => 40.0,
            Metric::Mae => 0.01,
        }
    }

    /// Larger values mean more similar (ssim, psnr).
    pub fn higher_is_better(self) -> bool {
        matches!(self, Metric::Ssim | Metric::Psnr)
    }

    pub fn passes(self, value: f64, threshold: f64) -> bool {
        if self.higher_is_better() {
            value >= threshold
        } else {
            value <= threshold
        }
    }
}

/// One comparison: the metric's value and a per-pixel error map in [0, 1]
/// (flip: FLIP error; ssim: (1 - ssim) / 2; psnr, mae: mean absolute
/// channel difference).
#[derive(Debug, Clone)]
pub struct Score {
    pub metric: Metric,
    pub value: f64,
    pub width: u32,
    pub height: u32,
    pub error_map: Vec<f32>,
}

impl Score {
    /// The error map through FLIP's magma color map (black: equal; the
    /// mae/psnr maps are shown as sqrt(error), so small differences show).
    pub fn diff_image(&self) -> Image8 {
        let lut = nv_flip::magma_lut().to_vec();
        let mut data = Vec::with_capacity(self.error_map.len() * 3);
        for &e in &self.error_map {
            let e = match self.metric {
                Metric::Psnr | Metric::Mae => e.max(0.0).sqrt(),
                _ => e,
            };
            let i = (e.clamp(0.0, 1.0) * 255.0).round() as usize;
            data.extend_from_slice(&lut[i * 3..i * 3 + 3]);
        }
        Image8 {
            width: self.width,
            height: self.height,
            channels: 3,
            data,
        }
    }
}

/// RGB bytes of `img` composited over a `bg` (0 or 255) background.
fn rgb_over(img: &Image8, bg: u8) -> Vec<u8> {
    match img.channels {
        3 => img.data.clone(),
        4 => img
            .data
            .chunks_exact(4)
            .flat_map(|p| {
                let a = p[3] as u32;
                [0, 1, 2].map(|k| ((p[k] as u32 * a + bg as u32 * (255 - a) + 127) / 255) as u8)
            })
            .collect(),
        1 => img.data.iter().flat_map(|&v| [v, v, v]).collect(),
        2 => img
            .data
            .chunks_exact(2)
            .flat_map(|p| {
                let a = p[1] as u32;
                let v = ((p[0] as u32 * a + bg as u32 * (255 - a) + 127) / 255) as u8;
                [v, v, v]
            })
            .collect(),
        _ => Vec::new(),
    }
}

/// Compares `test` with `reference`. Err when their sizes differ.
pub fn score(reference: &Image8, test: &Image8, metric: Metric) -> Result<Score, String> {
    if (reference.width, reference.height) != (test.width, test.height) {
        return Err(format!(
            "size differs: reference {}x{}, test {}x{}",
            reference.width, reference.height, test.width, test.height
        ));
    }
    let (w, h) = (reference.width, reference.height);
    let alpha = |i: &Image8| i.channels == 2 || i.channels == 4;
    let backgrounds: &[u8] = if alpha(reference) || alpha(test) {
        &[0, 255]
    } else {
        &[0]
    };
    let mut worst: Option<Score> = None;
    for &bg in backgrounds {
        let (a, b) = (rgb_over(reference, bg), rgb_over(test, bg));
        let s = score_rgb(&a, &b, w, h, metric);
        worst = Some(match worst {
            // Keep the earlier score unless the new one is worse.
            Some(prev) if metric.passes(s.value, prev.value) => prev,
            _ => s,
        });
    }
    worst.ok_or_else(|| "no pixels".to_string())
}

fn score_rgb(a: &[u8], b: &[u8], w: u32, h: u32, metric: Metric) -> Score {
    let n = (w as usize * h as usize).max(1);
    let abs_map = || -> Vec<f32> {
        a.par_chunks(3)
            .zip(b.par_chunks(3))
            .map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k]) as f32).sum::<f32>() / (3.0 * 255.0))
            .collect()
    };
    let (value, error_map) = match metric {
        Metric::Flip => {
            let r = nv_flip::FlipImageRgb8::with_data(w, h, a);
            let t = nv_flip::FlipImageRgb8::with_data(w, h, b);
            let map = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE).to_vec();
            let mean = map.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
            (mean, map)
        }
        Metric::Mae => {
            let map = abs_map();
            let mean = map.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
            (mean, map)
        }
        Metric::Psnr => {
            let se: f64 = a
                .iter()
                .zip(b)
                .map(|(&p, &q)| {
                    let d = (p as f64 - q as f64) / 255.0;
                    d * d
                })
                .sum();
            let mse = se / (3 * n) as f64;
            let psnr = if mse == 0.0 {
                100.0
            } else {
                (10.0 * (1.0 / mse).log10()).min(100.0)
            };
            (psnr, abs_map())
        }
        Metric::Ssim => {
            let ssim = ssim_map(&luma(a), &luma(b), w as usize, h as usize);
            let mean = ssim.iter().map(|&v| v as f64).sum::<f64>() / n as f64;
            let map = ssim
                .iter()
                .map(|&s| ((1.0 - s) * 0.5).clamp(0.0, 1.0))
                .collect();
            (mean, map)
        }
    };
    Score {
        metric,
        value,
        width: w,
        height: h,
        error_map,
    }
}

fn luma(rgb: &[u8]) -> Vec<f32> {
    rgb.chunks_exact(3)
        .map(|p| (0.2126 * p[0] as f32 + 0.7152 * p[1] as f32 + 0.0722 * p[2] as f32) / 255.0)
        .collect()
}

/// Per-pixel SSIM (Wang et al. 2004): Gaussian-weighted local means,
/// variances and covariance (11 taps, sigma 1.5, clamped at the borders),
/// C1 = 0.01^2, C2 = 0.03^2 for values in [0, 1].
fn ssim_map(x: &[f32], y: &[f32], w: usize, h: usize) -> Vec<f32> {
    let taps: Vec<f32> = {
        let k: Vec<f32> = (-5..=5i32)
            .map(|i| (-(i * i) as f32 / (2.0 * 1.5 * 1.5)).exp())
            .collect();
        let s: f32 = k.iter().sum();
        k.into_iter().map(|v| v / s).collect()
    };
    // One 11-tap pass along x or y, clamped at the borders.
    let pass = |src: &[f32], along_x: bool| -> Vec<f32> {
        let mut out = vec![0f32; w * h];
        out.par_chunks_mut(w).enumerate().for_each(|(yy, row)| {
            for (xx, o) in row.iter_mut().enumerate() {
                let mut acc = 0.0;
                for (t, &k) in taps.iter().enumerate() {
                    let d = t as i32 - 5;
                    let (sx, sy) = if along_x {
                        ((xx as i32 + d).clamp(0, w as i32 - 1) as usize, yy)
                    } else {
                        (xx, (yy as i32 + d).clamp(0, h as i32 - 1) as usize)
                    };
                    acc += k * src[sy * w + sx];
                }
                *o = acc;
            }
        });
        out
    };
    let blur = |img: &[f32]| pass(&pass(img, true), false);
    let prod = |a: &[f32], b: &[f32]| a.iter().zip(b).map(|(p, q)| p * q).collect::<Vec<f32>>();
    let (mx, my) = (blur(x), blur(y));
    let (sxx, syy, sxy) = (blur(&prod(x, x)), blur(&prod(y, y)), blur(&prod(x, y)));
    let (c1, c2) = (0.01f32 * 0.01, 0.03f32 * 0.03);
    (0..w * h)
        .map(|i| {
            let (ux, uy) = (mx[i], my[i]);
            let vx = (sxx[i] - ux * ux).max(0.0);
            let vy = (syy[i] - uy * uy).max(0.0);
            let cxy = sxy[i] - ux * uy;
            ((2.0 * ux * uy + c1) * (2.0 * cxy + c2)) / ((ux * ux + uy * uy + c1) * (vx + vy + c2))
        })
        .collect()
}

/// The outcome of one pair of files.
#[derive(Debug, Clone, PartialEq)]
pub enum Status {
    Pass,
    Fail,
    /// In the reference only (`Missing`) or in the test only (`Extra`).
    Missing,
    Extra,
    /// Unreadable or not an image: exit status 2.
    Error(String),
}

#[derive(Debug, Clone)]
pub struct FileResult {
    /// The file name (directories) or the test path (two files).
    pub name: String,
    pub status: Status,
    pub value: Option<f64>,
    /// Why a comparison failed beyond the value: a size difference, the
    /// side a file is missing from.
    pub message: Option<String>,
    pub diff: Option<PathBuf>,
    /// The pair's files (where each exists).
    pub reference: Option<PathBuf>,
    pub test: Option<PathBuf>,
}

impl FileResult {
    /// The status's name and what to say about it.
    fn describe(&self) -> (&'static str, Option<String>) {
        match &self.status {
            Status::Pass => ("pass", None),
            Status::Fail => ("fail", self.message.clone()),
            Status::Missing => ("missing", self.message.clone()),
            Status::Extra => ("extra", self.message.clone()),
            Status::Error(e) => ("error", Some(e.clone())),
        }
    }
}

#[derive(Debug, Clone)]
pub struct Report {
    pub metric: Metric,
    pub threshold: f64,
    pub files: Vec<FileResult>,
}

impl Report {
    /// 0: every pair passed; 1: some pair failed or a file is on one side
    /// only; 2: some file could not be read.
    pub fn exit_code(&self) -> i32 {
        if self.files.is_empty() {
            // A gate that compared nothing has not passed.
            return 1;
        }
        if self
            .files
            .iter()
            .any(|f| matches!(f.status, Status::Error(_)))
        {
            2
        } else if self.files.iter().all(|f| f.status == Status::Pass) {
            0
        } else {
            1
        }
    }

    pub fn to_json(&self) -> serde_json::Value {
        let files: Vec<_> = self
            .files
            .iter()
            .map(|f| {
                let (status, error) = f.describe();
                serde_json::json!({
                    "name": f.name,
                    "status": status,
                    "value": f.value,
                    "message": error,
                    "diff": f.diff,
                })
            })
            .collect();
        serde_json::json!({
            "metric": self.metric.name(),
            "threshold": self.threshold,
            "pass": self.exit_code() == 0,
            "exit_code": self.exit_code(),
            "files": files,
        })
    }

    /// The last line of `to_text`: how many pairs passed.
    pub fn summary(&self) -> String {
        let failed = self
            .files
            .iter()
            .filter(|f| f.status != Status::Pass)
            .count();
        format!(
            "{} of {} passed\n",
            self.files.len() - failed,
            self.files.len()
        )
    }

    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for f in &self.files {
            let (tag, detail) = f.describe();
            let (tag, detail) = (tag.to_uppercase(), detail.unwrap_or_default());
            let value = f
                .value
                .map(|v| {
                    let cmp = if self.metric.higher_is_better() {
                        ">="
                    } else {
                        "<="
                    };
                    format!(
                        " {}={v:.6} (pass: {cmp} {})",
                        self.metric.name(),
                        self.threshold
                    )
                })
                .unwrap_or_default();
            let sep = if detail.is_empty() { "" } else { ": " };
            out.push_str(&format!("{tag} {}{value}{sep}{detail}\n", f.name));
        }
        out.push_str(&self.summary());
        out
    }
}

fn is_image(p: &Path) -> bool {
    p.extension()
        .map(|e| e.to_string_lossy().to_ascii_lowercase())
        .is_some_and(|e| matches!(e.as_str(), "png" | "jpg" | "jpeg" | "tga"))
}

/// A PNG as it is, another image format as RGBA.
pub fn read_image(p: &Path) -> Result<Image8, String> {
    if p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png")) {
        return png::read(p).map_err(|e| e.to_string());
    }
    let img = png::read_any(p).map_err(|e| e.to_string())?;
    let rgba = img.to_rgba8();
    Ok(Image8 {
        width: rgba.width(),
        height: rgba.height(),
        channels: 4,
        data: rgba.into_raw(),
    })
}

/// Compares one pair; writes the diff image to `diff` when given.
fn compare_pair(
    name: String,
    reference: &Path,
    test: &Path,
    metric: Metric,
    threshold: f64,
    diff: Option<&Path>,
) -> FileResult {
    let result = |status, value, message, diff| FileResult {
        name: name.clone(),
        status,
        value,
        message,
        diff,
        reference: reference.exists().then(|| reference.to_path_buf()),
        test: test.exists().then(|| test.to_path_buf()),
    };
    for (path, side) in [(reference, "reference"), (test, "test")] {
        if !path.exists() {
            let msg = format!("{side} {} not found", path.display());
            return result(Status::Missing, None, Some(msg), None);
        }
    }
    let (a, b) = match (read_image(reference), read_image(test)) {
        (Ok(a), Ok(b)) => (a, b),
        (Err(e), _) | (_, Err(e)) => return result(Status::Error(e), None, None, None),
    };
    let s = match score(&a, &b, metric) {
        Ok(s) => s,
        Err(msg) => return result(Status::Fail, None, Some(msg), None),
    };
    let mut written = None;
    if let Some(d) = diff {
        if let Err(e) = png::write(d, &s.diff_image()) {
            return result(Status::Error(e.to_string()), Some(s.value), None, None);
        }
        written = Some(d.to_path_buf());
    }
    let status = if metric.passes(s.value, threshold) {
        Status::Pass
    } else {
        Status::Fail
    };
    result(status, Some(s.value), None, written)
}

/// Compares two images, or two directories of images paired by file name.
/// `diff`: a PNG file (two images) or a directory of `<name>.png` error
/// maps (two directories). Err only for a problem with the arguments
/// themselves (a directory against a file, an unreadable directory).
pub fn compare_paths(
    reference: &Path,
    test: &Path,
    metric: Metric,
    threshold: f64,
    diff: Option<&Path>,
) -> Result<Report, Error> {
    let files = if reference.is_dir() || test.is_dir() {
        if !(reference.is_dir() && test.is_dir()) {
            return Err(Error::Argument(format!(
                "{} and {}: compare two images or two directories",
                reference.display(),
                test.display()
            )));
        }
        let list = |dir: &Path| -> Result<std::collections::BTreeSet<String>, Error> {
            let mut names = std::collections::BTreeSet::new();
            for e in std::fs::read_dir(dir).map_err(|e| Error::io(dir, e))? {
                let e = e.map_err(|e| Error::io(dir, e))?;
                let p = e.path();
                if p.is_file() && is_image(&p) {
                    names.insert(e.file_name().to_string_lossy().into_owned());
                }
            }
            Ok(names)
        };
        let (r, t) = (list(reference)?, list(test)?);
        let names: Vec<&String> = r.union(&t).collect();
        names
            .par_iter()
            .map(|name| {
                let only = |status, message: &str| FileResult {
                    name: (*name).clone(),
                    status,
                    value: None,
                    message: Some(message.to_string()),
                    diff: None,
                    reference: r.contains(*name).then(|| reference.join(name.as_str())),
                    test: t.contains(*name).then(|| test.join(name.as_str())),
                };
                if !t.contains(*name) {
                    return only(Status::Missing, "not in the test set");
                }
                if !r.contains(*name) {
                    return only(Status::Extra, "not in the reference set");
                }
                let d = diff.map(|d| {
                    let stem = Path::new(name.as_str()).file_stem().unwrap_or_default();
                    d.join(format!("{}.png", stem.to_string_lossy()))
                });
                compare_pair(
                    (*name).clone(),
                    &reference.join(name.as_str()),
                    &test.join(name.as_str()),
                    metric,
                    threshold,
                    d.as_deref(),
                )
            })
            .collect()
    } else {
        vec![compare_pair(
            test.display().to_string(),
            reference,
            test,
            metric,
            threshold,
            diff,
        )]
    };
    Ok(Report {
        metric,
        threshold,
        files,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn img(w: u32, h: u32, f: impl Fn(u32, u32) -> [u8; 3]) -> Image8 {
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                data.extend_from_slice(&f(x, y));
            }
        }
        Image8 {
            width: w,
            height: h,
            channels: 3,
            data,
        }
    }

    #[test]
    fn identical_images_score_perfectly() {
        let a = img(40, 30, |x, y| [(x * 6) as u8, (y * 8) as u8, 90]);
        for m in [Metric::Flip, Metric::Ssim, Metric::Psnr, Metric::Mae] {
            let s = score(&a, &a, m).unwrap();
            let perfect = match m {
                Metric::Ssim => 1.0,
                Metric::Psnr => 100.0,
                _ => 0.0,
            };
            assert!((s.value - perfect).abs() < 1e-6, "{m:?}: {}", s.value);
            assert!(m.passes(s.value, m.default_threshold()));
        }
    }

    #[test]
    fn known_values_and_ordering() {
        let a = img(32, 32, |_, _| [100, 100, 100]);
        let b = img(32, 32, |_, _| [110, 100, 100]);
        // MAE: 10/255 on one channel of three.
        let mae = score(&a, &b, Metric::Mae).unwrap().value;
        assert!((mae - 10.0 / 765.0).abs() < 1e-6);
        // PSNR: MSE = (10/255)^2 / 3.
        let psnr = score(&a, &b, Metric::Psnr).unwrap().value;
        let want = 10.0 * (3.0 / (10.0f64 / 255.0).powi(2)).log10();
        assert!((psnr - want).abs() < 1e-6, "{psnr} vs {want}");
        // FLIP grows with the difference.
        let c = img(32, 32, |_, _| [200, 40, 100]);
        let f1 = score(&a, &b, Metric::Flip).unwrap().value;
        let f2 = score(&a, &c, Metric::Flip).unwrap().value;
        assert!(0.0 < f1 && f1 < f2, "{f1} {f2}");
        assert!(score(&a, &img(31, 32, |_, _| [0; 3]), Metric::Flip).is_err());
    }

    #[test]
    fn alpha_alone_makes_a_difference() {
        let rgba = |a: u8| Image8 {
            width: 8,
            height: 8,
            channels: 4,
            data: [0, 0, 0, a].repeat(64),
        };
        let s = score(&rgba(255), &rgba(0), Metric::Mae).unwrap();
        assert!(s.value > 0.9, "{}", s.value);
    }
}
