//! The review page for golden-frame CI (`softraster compare --report`):
//! one self-contained HTML file, every image embedded as a PNG data URI,
//! one row per file with reference, test, error map, the metric and the
//! verdict, failures first. Failing pairs are shown at full size; passing
//! ones as thumbnails, so a 72-frame report stays a few megabytes. And
//! `--update`, which blesses the test images as the new references.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use base64::Engine as _;
use rayon::prelude::*;

use super::compare::{FileResult, Report, Status, read_image, score};
use softraster::error::Error;
use softraster::output::{Image8, write_atomic};

/// Longest side of a passing pair's images in the page.
const THUMBNAIL: u32 = 256;

/// Writes the review page of `report` to `out`.
pub fn write_html(report: &Report, out: &Path) -> Result<(), Error> {
    let mut order: Vec<&FileResult> = report.files.iter().collect();
    // Failures first (errors, then fails, then files on one side), then
    // passes; by name within each.
    let rank = |f: &FileResult| match f.status {
        Status::Error(_) => 0,
        Status::Fail => 1,
        Status::Missing | Status::Extra => 2,
        Status::Pass => 3,
    };
    order.sort_by(|a, b| rank(a).cmp(&rank(b)).then(a.name.cmp(&b.name)));
    let rows: Vec<String> = order
        .par_iter()
        .map(|f| row(report, f))
        .collect::<Result<_, Error>>()?;
    let failed = report
        .files
        .iter()
        .filter(|f| f.status != Status::Pass)
        .count();
    let cmp = if report.metric.higher_is_better() {
        ">="
    } else {
        "<="
    };
    let mut page = String::new();
    let _ = write!(
        page,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <title>softraster compare: {failed} of {total} failed</title>\n<style>\n\
         body {{ font-family: system-ui, sans-serif; margin: 1.5em; background: #f4f4f4; }}\n\
         table {{ border-collapse: collapse; }}\n\
         td, th {{ padding: 6px 10px; vertical-align: top; border-bottom: 1px solid #ccc; text-align: left; }}\n\
         img {{ image-rendering: pixelated; max-width: 100%; background: repeating-conic-gradient(#ddd 0 25%, #fff 0 50%) 0 0 / 16px 16px; }}\n\
         .pass {{ color: #176317; font-weight: bold; }} .fail {{ color: #b00020; font-weight: bold; }}\n\
         </style></head><body>\n\
         <h1>{failed} of {total} failed</h1>\n\
         <p>Metric <b>{metric}</b>, pass when {cmp} {threshold}. Error maps: black is equal \
         (magma colour map; mae and psnr maps show the square root of the error).</p>\n\
         <table><tr><th>file</th><th>verdict</th><th>reference</th><th>test</th><th>error map</th></tr>\n",
        total = report.files.len(),
        metric = report.metric.name(),
        threshold = report.threshold,
    );
    for r in rows {
        page.push_str(&r);
    }
    page.push_str("</table>\n</body></html>\n");
    write_atomic(out, |w| {
        use std::io::Write;
        w.write_all(page.as_bytes()).map_err(|e| Error::io(out, e))
    })
}

/// One table row: names, verdict and the three images.
fn row(report: &Report, f: &FileResult) -> Result<String, Error> {
    let (verdict, class) = match &f.status {
        Status::Pass => ("pass".to_string(), "pass"),
        Status::Fail => ("FAIL".to_string(), "fail"),
        Status::Missing => ("missing from the test set".to_string(), "fail"),
        Status::Extra => ("not in the references".to_string(), "fail"),
        Status::Error(e) => (format!("error: {}", escape(e)), "fail"),
    };
    let value = f
        .value
        .map(|v| format!("<br>{} = {v:.6}", report.metric.name()))
        .unwrap_or_default();
    let message = f
        .message
        .as_ref()
        .map(|m| format!("<br>{}", escape(m)))
        .unwrap_or_default();
    let full = f.status != Status::Pass;
    let read = |p: &Option<PathBuf>| p.as_ref().and_then(|p| read_image(p).ok());
    let (a, b) = (read(&f.reference), read(&f.test));
    let diff = match (&a, &b) {
        (Some(a), Some(b)) => score(a, b, report.metric).ok().map(|s| s.diff_image()),
        _ => None,
    };
    let cell = |img: &Option<Image8>, path: &Option<PathBuf>| -> Result<String, Error> {
        let title = path
            .as_ref()
            .map(|p| escape(&p.display().to_string()))
            .unwrap_or_default();
        Ok(match img {
            Some(img) => format!(
                "<td><img title=\"{title}\" src=\"data:image/png;base64,{}\"></td>",
                data_uri(img, full)?
            ),
            None => "<td>-</td>".to_string(),
        })
    };
    Ok(format!(
        "<tr><td>{name}</td><td><span class=\"{class}\">{verdict}</span>{value}{message}</td>{}{}{}</tr>\n",
        cell(&a, &f.reference)?,
        cell(&b, &f.test)?,
        cell(&diff, &None)?,
        name = escape(&f.name),
    ))
}

/// Base64 PNG of `img`, shrunk to a thumbnail unless `full`.
fn data_uri(img: &Image8, full: bool) -> Result<String, Error> {
    let color = if img.channels == 4 {
        image::ExtendedColorType::Rgba8
    } else {
        image::ExtendedColorType::Rgb8
    };
    let (mut w, mut h, mut data) = (img.width, img.height, img.data.clone());
    if !full && w.max(h) > THUMBNAIL {
        let s = THUMBNAIL as f32 / w.max(h) as f32;
        let (tw, th) = (
            ((w as f32 * s) as u32).max(1),
            ((h as f32 * s) as u32).max(1),
        );
        let resized = if img.channels == 4 {
            let i = image::RgbaImage::from_raw(w, h, data).unwrap_or_default();
            image::imageops::thumbnail(&i, tw, th).into_raw()
        } else {
            let i = image::RgbImage::from_raw(w, h, data).unwrap_or_default();
            image::imageops::thumbnail(&i, tw, th).into_raw()
        };
        (w, h, data) = (tw, th, resized);
    }
    let mut bytes = Vec::new();
    image::ImageEncoder::write_image(
        image::codecs::png::PngEncoder::new(&mut bytes),
        &data,
        w,
        h,
        color,
    )
    .map_err(|e| Error::Render(format!("report image: {e}")))?;
    Ok(base64::engine::general_purpose::STANDARD.encode(bytes))
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// `--update`: copies each failing test image over its reference (and,
/// for two directories, adds test images the references lack to
/// `references`), printing what changed. Returns the files updated.
pub fn update_references(report: &Report, references: &Path) -> Result<Blessed, Error> {
    let mut blessed = Blessed::default();
    for f in &report.files {
        let target = match (&f.status, &f.reference, &f.test) {
            (Status::Fail, Some(r), Some(_)) => r.clone(),
            (Status::Extra, None, Some(_)) if references.is_dir() => references.join(&f.name),
            _ => continue,
        };
        let Some(test) = &f.test else { continue };
        let bytes = std::fs::read(test).map_err(|e| Error::io(test, e))?;
        write_atomic(&target, |w| {
            use std::io::Write;
            w.write_all(&bytes).map_err(|e| Error::io(&target, e))
        })?;
        let why = match (&f.status, f.value) {
            (Status::Extra, _) => "new reference".to_string(),
            (_, Some(v)) => format!("{} = {v:.6}", report.metric.name()),
            (_, None) => f.message.clone().unwrap_or_default(),
        };
        eprintln!("updated {} <- {} ({why})", target.display(), test.display());
        if f.status == Status::Extra {
            blessed.new.push(target);
        } else {
            blessed.changed.push(target);
        }
    }
    blessed.unchanged = report
        .files
        .iter()
        .filter(|f| f.status == Status::Pass)
        .count();
    Ok(blessed)
}

/// What `update_references` wrote: references added, references replaced,
/// and the pairs that already passed.
#[derive(Debug, Default)]
pub struct Blessed {
    pub new: Vec<PathBuf>,
    pub changed: Vec<PathBuf>,
    pub unchanged: usize,
}

impl std::fmt::Display for Blessed {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "blessed {} new, {} changed ({} unchanged)",
            self.new.len(),
            self.changed.len(),
            self.unchanged
        )
    }
}
