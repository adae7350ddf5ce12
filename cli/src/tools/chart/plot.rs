//! The chart: time (x, log) against error (y, log), one series per knob in
//! the order of its settings, each knob's Pareto front as a dashed line,
//! softraster's defaults ringed and labelled, the settings on a front
//! named. Errors of 0 (the references,
//! and exact settings) sit on the bottom edge as triangles. Drawn with
//! plotters into a PNG (text in DejaVu Sans, embedded by the dejavu crate)
//! and an SVG.

use std::path::Path;

use plotters::coord::Shift;
use plotters::prelude::*;

use super::{Knob, Row};
use softraster::error::Error;
use softraster::output::{self, Image8};

const SIZE: (u32, u32) = (1100, 700);

fn color(k: Knob) -> RGBColor {
    match k {
        Knob::Aa => RGBColor(31, 119, 180),
        Knob::Texture => RGBColor(255, 127, 14),
        Knob::Shadows => RGBColor(44, 160, 44),
        Knob::Ao => RGBColor(214, 39, 40),
        Knob::Depth => RGBColor(148, 103, 189),
        Knob::Env => RGBColor(140, 86, 75),
    }
}

fn label(k: Knob) -> &'static str {
    match k {
        Knob::Aa => "anti-aliasing (FLIP)",
        Knob::Texture => "texture filter (FLIP, interior)",
        Knob::Shadows => "shadows (FLIP)",
        Knob::Ao => "ambient occlusion (RMSE)",
        Knob::Depth => "depth mode (failure fraction)",
        Knob::Env => "environment lighting (FLIP)",
    }
}

fn register_font() {
    static ONCE: std::sync::Once = std::sync::Once::new();
    ONCE.call_once(|| {
        // The font is a valid TTF compiled into the binary.
        let _ = plotters::style::register_font(
            "sans-serif",
            FontStyle::Normal,
            dejavu::sans::regular(),
        );
    });
}

/// The log axes' ranges (time, error) and the floor where zero errors
/// are drawn, a factor below the smallest error.
fn axes(rows: &[Row]) -> (std::ops::Range<f64>, std::ops::Range<f64>, f64) {
    let times: Vec<f64> = rows.iter().map(|r| r.time.median_ms.max(1e-3)).collect();
    let positive: Vec<f64> = rows.iter().map(|r| r.error).filter(|e| *e > 0.0).collect();
    let (tmin, tmax) = times
        .iter()
        .fold((f64::INFINITY, 0f64), |(a, b), &t| (a.min(t), b.max(t)));
    let (emin, emax) = positive
        .iter()
        .fold((f64::INFINITY, 0f64), |(a, b), &e| (a.min(e), b.max(e)));
    let (emin, emax) = if positive.is_empty() {
        (1e-4, 1.0)
    } else {
        (emin, emax)
    };
    let floor = emin / 4.0;
    (
        (tmin / 1.6)..(tmax * 1.6),
        (floor / 1.5)..(emax * 2.0),
        floor,
    )
}

/// A setting's name on the chart.
fn setting_label(r: &Row) -> String {
    if r.default {
        format!("{} (default)", r.setting)
    } else {
        r.setting.clone()
    }
}

/// A Pareto front's points as a staircase, by increasing time.
fn staircase(mut front: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    front.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut stairs = Vec::new();
    for (i, p) in front.iter().enumerate() {
        if i > 0 {
            stairs.push((p.0, front[i - 1].1));
        }
        stairs.push(*p);
    }
    stairs
}

fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[Row],
    title: &str,
) -> Result<(), String>
where
    DB::ErrorType: 'static,
{
    let err = |e: &dyn std::fmt::Display| e.to_string();
    root.fill(&WHITE).map_err(|e| err(&e))?;
    let (x, y, floor) = axes(rows);
    let mut chart = ChartBuilder::on(root)
        .caption(title, ("sans-serif", 22))
        .margin(16)
        .x_label_area_size(50)
        .y_label_area_size(80)
        .build_cartesian_2d(x.log_scale(), y.log_scale())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .x_desc("wall time of the frame, ms (median; bars: min-max)")
        .y_desc("error against the knob's reference (0 on the floor)")
        .label_style(("sans-serif", 14))
        .axis_desc_style(("sans-serif", 16))
        .light_line_style(RGBColor(235, 235, 235))
        .draw()
        .map_err(|e| err(&e))?;
    let at = |r: &Row| {
        (
            r.time.median_ms.max(1e-3),
            if r.error > 0.0 { r.error } else { floor },
        )
    };
    for k in Knob::ALL {
        let ks: Vec<&Row> = rows.iter().filter(|r| r.knob == k).collect();
        if ks.is_empty() {
            continue;
        }
        let c = color(k);
        // The settings in sweep order (without the reference).
        let line: Vec<(f64, f64)> = ks.iter().filter(|r| !r.reference).map(|r| at(r)).collect();
        chart
            .draw_series(LineSeries::new(line, c.mix(0.5).stroke_width(1)))
            .map_err(|e| err(&e))?
            .label(label(k))
            .legend(move |(x, y)| Circle::new((x + 10, y), 5, c.filled()));
        // Pareto fronts (one per reference: AO has one per radius): dashed
        // staircases through the non-dominated points.
        let mut groups: Vec<&str> = ks.iter().map(|r| r.against.as_str()).collect();
        groups.dedup();
        for g in groups {
            let front = ks
                .iter()
                .filter(|r| r.pareto && r.against == g)
                .map(|r| at(r));
            let stairs = staircase(front.collect());
            chart
                .draw_series(DashedLineSeries::new(stairs, 6, 4, c.stroke_width(2)))
                .map_err(|e| err(&e))?;
        }
        // Time spread bars.
        chart
            .draw_series(ks.iter().map(|r| {
                let (_, ey) = at(r);
                PathElement::new(
                    vec![(r.time.min_ms.max(1e-3), ey), (r.time.max_ms.max(1e-3), ey)],
                    c.stroke_width(1),
                )
            }))
            .map_err(|e| err(&e))?;
        chart
            .draw_series(ks.iter().map(|r| {
                let p = at(r);
                let style = if r.pareto {
                    c.filled()
                } else {
                    c.stroke_width(2)
                };
                // Zero errors get a triangle on the floor instead.
                let radius = if r.error > 0.0 { 5 } else { 0 };
                EmptyElement::at(p) + Circle::new((0, 0), radius, style)
            }))
            .map_err(|e| err(&e))?;
        chart
            .draw_series(
                ks.iter()
                    .filter(|r| r.error <= 0.0)
                    .map(|r| TriangleMarker::new(at(r), 7, c.filled())),
            )
            .map_err(|e| err(&e))?;
        // Names of the settings on a front and of the default (the
        // dominated ones are in the CSV), and the default ringed.
        chart
            .draw_series(ks.iter().filter(|r| r.pareto || r.default).map(|r| {
                let style = ("sans-serif", 11).into_font().color(&c);
                EmptyElement::at(at(r)) + Text::new(setting_label(r), (7, -14), style)
            }))
            .map_err(|e| err(&e))?;
        chart
            .draw_series(
                ks.iter()
                    .filter(|r| r.default)
                    .map(|r| Circle::new(at(r), 10, BLACK.stroke_width(2))),
            )
            .map_err(|e| err(&e))?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .label_font(("sans-serif", 14))
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(|e| err(&e))?;
    root.present().map_err(|e| err(&e))?;
    Ok(())
}

/// Writes the chart as PNG and SVG (each atomically).
pub fn write(rows: &[Row], title: &str, png: &Path, svg: &Path) -> Result<(), Error> {
    register_font();
    let fail = |p: &Path, m: String| Error::Encode {
        path: p.to_path_buf(),
        message: m,
    };
    let mut buf = vec![0u8; (SIZE.0 * SIZE.1 * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buf, SIZE).into_drawing_area();
        draw(&root, rows, title).map_err(|m| fail(png, m))?;
    }
    output::png::write(
        png,
        &Image8 {
            width: SIZE.0,
            height: SIZE.1,
            channels: 3,
            data: buf,
        },
    )?;
    let mut text = String::new();
    {
        let root = SVGBackend::with_string(&mut text, SIZE).into_drawing_area();
        draw(&root, rows, title).map_err(|m| fail(svg, m))?;
    }
    output::write_atomic(svg, |w| {
        use std::io::Write;
        w.write_all(text.as_bytes()).map_err(|e| Error::io(svg, e))
    })
}
