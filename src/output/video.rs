//! H.264 video in an MP4 container, without a system ffmpeg: frames are
//! converted to YUV 4:2:0 here (BT.601 limited range, rounded), encoded by
//! Cisco's OpenH264 (the `openh264` crate, BSD-2-Clause, built from its
//! bundled source) and muxed by `muxide` (MIT/Apache) with the index first
//! ("fast start"), so browsers, chat apps and QuickTime play the file
//! while it downloads.
//!
//! Frames stream in as they finish (`VideoWriter::push`); only the encoded
//! stream is kept until `finish`, which writes the file atomically (a
//! temporary name, then a rename). 4:2:0 needs even sizes: an odd width or
//! height is padded by repeating the last column or row, and the stream and
//! container declare the padded size.
//!
//! Patent note: H.264 is patent-encumbered. Cisco pays the royalties only
//! for its own prebuilt binaries; a build from source (what this crate
//! does) is not covered by that licence. See the `openh264` crate's
//! documentation.

use std::path::{Path, PathBuf};

use openh264::encoder::{
    BitRate, Complexity, Encoder, EncoderConfig, FrameRate, IntraFramePeriod, QpRange,
    RateControlMode, SpsPpsStrategy, UsageType, VuiConfig,
};
use openh264::formats::YUVSlices;
use openh264::{OpenH264API, Timestamp};

use super::Image8;
use crate::error::Error;
pub use crate::scene::settings::{VideoQuality, check_video_size};

/// How the video writer encodes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VideoOptions {
    /// Frames per second (constant frame rate).
    pub fps: f64,
    /// A quality from 1 to 100 or a bit rate.
    pub quality: VideoQuality,
}

/// What was written.
#[derive(Debug, Clone, PartialEq)]
pub struct VideoInfo {
    /// Frames written.
    pub frames: usize,
    /// The stream's size (the frames' size rounded up to even).
    pub width: u32,
    /// The stream's height.
    pub height: u32,
    /// Frames per second.
    pub fps: f64,
    /// The file's size.
    pub bytes: u64,
}

/// Planar YUV 4:2:0 of an RGB(A) image (alpha ignored), BT.601 limited
/// range, rounded; odd sizes padded to even by repeating the last column
/// and row. Returns (Y, U, V, padded width, padded height).
///
/// Plain subsampling loses a lot at saturated edges (rendered frames are
/// full of them: coloured lights, sharp shadows). So, as libwebp's "sharp
/// YUV" does, the conversion aims at what a player shows, chroma
/// upsampled bilinearly (`yuv420_to_rgb`): the chroma planes are refined
/// by back-projection (their upsampled error, filtered down, is added
/// back), then each pixel's luma is the one that brings its R, G and B
/// closest to the original given the chroma the player will have there.
pub fn rgb_to_yuv420(img: &Image8) -> (Vec<u8>, Vec<u8>, Vec<u8>, usize, usize) {
    let (w, h) = (img.width as usize, img.height as usize);
    let (pw, ph) = (w.next_multiple_of(2), h.next_multiple_of(2));
    let ch = img.channels as usize;
    let rgb: Vec<[f32; 3]> = (0..pw * ph)
        .map(|i| {
            let (x, y) = ((i % pw).min(w - 1), (i / pw).min(h - 1));
            let d = &img.data[(y * w + x) * ch..][..3];
            [d[0] as f32, d[1] as f32, d[2] as f32]
        })
        .collect();
    // Rec. 601 (Kr = 0.299, Kb = 0.114), 8-bit studio range.
    let cb = |c: &[f32; 3]| 128.0 + (-37.797 * c[0] - 74.203 * c[1] + 112.0 * c[2]) / 255.0;
    let cr = |c: &[f32; 3]| 128.0 + (112.0 * c[0] - 93.786 * c[1] - 18.214 * c[2]) / 255.0;
    let byte = |v: f32| v.round().clamp(0.0, 255.0) as u8;
    let (cw, chh) = (pw / 2, ph / 2);
    // Full-resolution chroma, the target.
    let full_u: Vec<f32> = rgb.iter().map(cb).collect();
    let full_v: Vec<f32> = rgb.iter().map(cr).collect();
    // Chroma sited as H.264 assumes by default (type 0): horizontally on
    // the even luma column, vertically between the two rows; each sample
    // filters its two rows with [1, 2, 1] / 4 across.
    let down = |full: &[f32]| -> Vec<f32> {
        let mut out = vec![0.0f32; cw * chh];
        for cy in 0..chh {
            for cx in 0..cw {
                let x = cx * 2;
                let mut m = 0.0;
                for dy in 0..2 {
                    let row = &full[(cy * 2 + dy) * pw..][..pw];
                    m += row[x.saturating_sub(1)] * 0.125 + row[x] * 0.25 + row[x + 1] * 0.125;
                }
                out[cy * cw + cx] = m;
            }
        }
        out
    };
    let up = |plane: &[f32]| -> Vec<f32> {
        let mut out = vec![0.0f32; pw * ph];
        for y in 0..ph {
            for x in 0..pw {
                out[y * pw + x] = upsample(plane, cw, chh, cw, x, y);
            }
        }
        out
    };
    let refine = |full: &[f32]| -> Vec<u8> {
        let mut plane = down(full);
        for _ in 0..2 {
            let shown = up(&plane);
            let err: Vec<f32> = full.iter().zip(&shown).map(|(a, b)| a - b).collect();
            for (p, e) in plane.iter_mut().zip(down(&err)) {
                *p = (*p + e).clamp(0.0, 255.0);
            }
        }
        plane.iter().map(|&v| byte(v)).collect()
    };
    let u_plane = refine(&full_u);
    let v_plane = refine(&full_v);
    // Luma given the chroma the player reconstructs: R, G and B each grow
    // by 255/219 per luma step, so the least-squares luma matches the
    // mean of the channels' remainders.
    let uf: Vec<f32> = u_plane.iter().map(|&v| v as f32).collect();
    let vf: Vec<f32> = v_plane.iter().map(|&v| v as f32).collect();
    let mut y_plane = vec![0u8; pw * ph];
    for y in 0..ph {
        for x in 0..pw {
            let u = (upsample(&uf, cw, chh, cw, x, y) - 128.0) * 255.0 / 224.0;
            let v = (upsample(&vf, cw, chh, cw, x, y) - 128.0) * 255.0 / 224.0;
            let c = &rgb[y * pw + x];
            let rest = [1.402 * v, -0.344_136 * u - 0.714_136 * v, 1.772 * u];
            let l = (0..3).map(|k| c[k] - rest[k]).sum::<f32>() / 3.0;
            y_plane[y * pw + x] = byte(16.0 + l * 219.0 / 255.0);
        }
    }
    (y_plane, u_plane, v_plane, pw, ph)
}

/// A chroma plane (`cw` x `ch`, `stride`) at luma pixel (x, y): bilinear
/// from the type-0 siting, sample (i, j) at luma (2i, 2j + 0.5).
fn upsample(plane: &[f32], cw: usize, ch: usize, stride: usize, x: usize, y: usize) -> f32 {
    let fx = x as f32 / 2.0;
    let fy = ((y as f32 - 0.5) / 2.0).max(0.0);
    let (i0, j0) = ((fx as usize).min(cw - 1), (fy as usize).min(ch - 1));
    let (i1, j1) = ((i0 + 1).min(cw - 1), (j0 + 1).min(ch - 1));
    let (tx, ty) = (fx - i0 as f32, fy - j0 as f32);
    let at = |i: usize, j: usize| plane[j * stride + i];
    let top = at(i0, j0) * (1.0 - tx) + at(i1, j0) * tx;
    let bottom = at(i0, j1) * (1.0 - tx) + at(i1, j1) * tx;
    top * (1.0 - ty) + bottom * ty
}

/// The inverse of `rgb_to_yuv420`: RGB of planar 4:2:0 (`width` x
/// `height`, strides given), chroma upsampled bilinearly from its type-0
/// siting, as players show it.
pub fn yuv420_to_rgb(
    planes: (&[u8], &[u8], &[u8]),
    strides: (usize, usize, usize),
    width: usize,
    height: usize,
) -> Vec<u8> {
    let (yp, up, vp) = planes;
    let (cw, ch) = (width.div_ceil(2), height.div_ceil(2));
    let to_f32 = |p: &[u8]| p.iter().map(|&v| v as f32).collect::<Vec<f32>>();
    let (uf, vf) = (to_f32(up), to_f32(vp));
    let mut out = Vec::with_capacity(width * height * 3);
    for y in 0..height {
        for x in 0..width {
            out.extend_from_slice(&ycbcr_to_rgb(
                yp[y * strides.0 + x] as f32,
                upsample(&uf, cw, ch, strides.1, x, y),
                upsample(&vf, cw, ch, strides.2, x, y),
            ));
        }
    }
    out
}

/// The inverse of `rgb_to_yuv420` for one pixel.
pub fn yuv_to_rgb(y: u8, u: u8, v: u8) -> [u8; 3] {
    ycbcr_to_rgb(y as f32, u as f32, v as f32)
}

fn ycbcr_to_rgb(y: f32, u: f32, v: f32) -> [u8; 3] {
    let y = (y - 16.0) * 255.0 / 219.0;
    let u = (u - 128.0) * 255.0 / 224.0;
    let v = (v - 128.0) * 255.0 / 224.0;
    let r = y + 1.402 * v;
    let g = y - 0.344_136 * u - 0.714_136 * v;
    let b = y + 1.772 * u;
    let byte = |x: f32| x.round().clamp(0.0, 255.0) as u8;
    [byte(r), byte(g), byte(b)]
}

/// A video being written: frames go in one at a time.
pub struct VideoWriter {
    path: PathBuf,
    opts: VideoOptions,
    /// The frames' size (all frames must have it) and the stream's.
    size: (u32, u32),
    padded: (u32, u32),
    encoder: Encoder,
    /// Muxed in memory (the file appears whole, when finished: a killed
    /// render leaves nothing behind).
    muxer: Option<muxide::api::Muxer<Vec<u8>>>,
    frames: usize,
    nal: Vec<u8>,
}

fn enc_err(path: &Path, what: impl std::fmt::Display) -> Error {
    Error::Encode {
        path: path.to_path_buf(),
        message: what.to_string(),
    }
}

impl VideoWriter {
    /// Starts `path` (an `.mp4`) for frames of `width` x `height`.
    pub fn create(
        path: &Path,
        width: u32,
        height: u32,
        opts: VideoOptions,
    ) -> Result<VideoWriter, Error> {
        check_video_size(width, height).map_err(|m| enc_err(path, m))?;
        if !(opts.fps.is_finite() && opts.fps > 0.0 && opts.fps <= 240.0) {
            return Err(enc_err(
                path,
                format!("{} frames per second: expected 0 < fps <= 240", opts.fps),
            ));
        }
        let padded = (width.next_multiple_of(2), height.next_multiple_of(2));
        let mut config = EncoderConfig::new()
            .skip_frames(false)
            .usage_type(UsageType::CameraVideoRealTime)
            .complexity(Complexity::High)
            .max_frame_rate(FrameRate::from_hz(opts.fps as f32))
            .sps_pps_strategy(SpsPpsStrategy::ConstantId)
            // One thread: the stream is then the same on every machine.
            .num_threads(1)
            // A key frame every two seconds, so players can seek.
            .intra_frame_period(IntraFramePeriod::from_num_frames(
                (opts.fps * 2.0).round().max(1.0) as u32,
            ))
            .scene_change_detect(false)
            .background_detection(false)
            .vui(VuiConfig::bt601());
        config = match opts.quality {
            VideoQuality::Quality(q) => {
                let qp = VideoQuality::qp(q);
                config
                    .rate_control_mode(RateControlMode::Bufferbased)
                    .qp(QpRange::new(qp, qp))
                    .adaptive_quantization(false)
                    .bitrate(BitRate::from_bps(50_000_000))
            }
            VideoQuality::Bitrate(bps) => config
                .rate_control_mode(RateControlMode::Bitrate)
                .bitrate(BitRate::from_bps(bps)),
        };
        let encoder = Encoder::with_api_config(OpenH264API::from_source(), config)
            .map_err(|e| enc_err(path, format!("cannot start the H.264 encoder: {e}")))?;
        super::check_target(path)?;
        let muxer = muxide::api::MuxerBuilder::new(Vec::new())
            .video(muxide::api::VideoCodec::H264, padded.0, padded.1, opts.fps)
            .with_fast_start(true)
            .build()
            .map_err(|e| enc_err(path, e))?;
        Ok(VideoWriter {
            path: path.to_path_buf(),
            opts,
            size: (width, height),
            padded,
            encoder,
            muxer: Some(muxer),
            frames: 0,
            nal: Vec::new(),
        })
    }

    /// Where the video goes.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Encodes the next frame.
    pub fn push(&mut self, img: &Image8) -> Result<(), Error> {
        if (img.width, img.height) != self.size {
            return Err(enc_err(
                &self.path,
                format!(
                    "frame {} is {}x{}, the video's frames are {}x{}",
                    self.frames, img.width, img.height, self.size.0, self.size.1
                ),
            ));
        }
        let (y, u, v, pw, ph) = rgb_to_yuv420(img);
        let source = YUVSlices::new((&y, &u, &v), (pw, ph), (pw, pw / 2, pw / 2));
        let ms = (self.frames as f64 * 1000.0 / self.opts.fps).round() as u64;
        let stream = self
            .encoder
            .encode_at(&source, Timestamp::from_millis(ms))
            .map_err(|e| enc_err(&self.path, format!("frame {}: {e}", self.frames)))?;
        self.nal.clear();
        stream.write_vec(&mut self.nal);
        let key = matches!(
            stream.frame_type(),
            openh264::encoder::FrameType::IDR | openh264::encoder::FrameType::I
        );
        if self.nal.is_empty() {
            return Err(enc_err(
                &self.path,
                format!("frame {}: the encoder returned no data", self.frames),
            ));
        }
        let pts = self.frames as f64 / self.opts.fps;
        let muxer = self
            .muxer
            .as_mut()
            .ok_or_else(|| enc_err(&self.path, "the video is finished"))?;
        muxer
            .write_video(pts, &self.nal, key)
            .map_err(|e| enc_err(&self.path, format!("frame {}: {e}", self.frames)))?;
        self.frames += 1;
        Ok(())
    }

    /// Writes the index, then the file (atomically).
    pub fn finish(mut self) -> Result<VideoInfo, Error> {
        if self.frames == 0 {
            return Err(enc_err(&self.path, "a video needs at least one frame"));
        }
        let mut muxer = self
            .muxer
            .take()
            .ok_or_else(|| enc_err(&self.path, "the video is finished"))?;
        muxer
            .finish_in_place()
            .map_err(|e| enc_err(&self.path, e))?;
        let data = muxer.into_writer();
        super::write_bytes_atomic(&self.path, &data)?;
        let bytes = data.len() as u64;
        Ok(VideoInfo {
            frames: self.frames,
            width: self.padded.0,
            height: self.padded.1,
            fps: self.opts.fps,
            bytes,
        })
    }
}

/// Assembles `frames` (PNG files, in order, all of one size) into `out`.
pub fn assemble(frames: &[PathBuf], out: &Path, opts: VideoOptions) -> Result<VideoInfo, Error> {
    let first = frames
        .first()
        .ok_or_else(|| Error::Argument("a video needs at least one frame".into()))?;
    // The size from the header first: a frame too large for a video is
    // refused before it is decoded.
    let (w, h) = image::image_dimensions(first)
        .map_err(|e| Error::asset(first, None, format!("cannot read the frame: {e}")))?;
    check_video_size(w, h).map_err(|m| Error::asset(first, None, m))?;
    let img = super::png::read(first)?;
    let mut writer = VideoWriter::create(out, img.width, img.height, opts)?;
    writer.push(&img)?;
    for p in &frames[1..] {
        let img = super::png::read(p)?;
        if (img.width, img.height) != (writer.size.0, writer.size.1) {
            return Err(Error::asset(
                p,
                None,
                format!(
                    "frame is {}x{}, the first frame ({}) is {}x{}",
                    img.width,
                    img.height,
                    first.display(),
                    writer.size.0,
                    writer.size.1
                ),
            ));
        }
        writer.push(&img)?;
    }
    writer.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_round_trips_within_rounding() {
        // Flat 2x2 blocks (no chroma averaging): every color comes back
        // within the 8-bit studio range's rounding.
        for c in [[0u8, 0, 0], [255, 255, 255], [200, 30, 90], [12, 240, 128]] {
            let img = Image8 {
                width: 2,
                height: 2,
                channels: 3,
                data: c.repeat(4),
            };
            let (y, u, v, ..) = rgb_to_yuv420(&img);
            let back = yuv_to_rgb(y[0], u[0], v[0]);
            for k in 0..3 {
                assert!(
                    (back[k] as i32 - c[k] as i32).abs() <= 2,
                    "{c:?} -> {back:?}"
                );
            }
        }
        // Known values: white is Y 235, black 16, chroma neutral 128.
        let white = Image8 {
            width: 2,
            height: 2,
            channels: 3,
            data: vec![255; 12],
        };
        let (y, u, v, ..) = rgb_to_yuv420(&white);
        assert_eq!((y[0], u[0], v[0]), (235, 128, 128));
    }

    #[test]
    fn odd_sizes_pad_by_repeating_the_edge() {
        let mut data = Vec::new();
        for y in 0..3u8 {
            for x in 0..3u8 {
                data.extend_from_slice(&[x * 100, y * 100, 0]);
            }
        }
        let img = Image8 {
            width: 3,
            height: 3,
            channels: 3,
            data,
        };
        let (y, u, v, pw, ph) = rgb_to_yuv420(&img);
        assert_eq!((pw, ph, y.len(), u.len()), (4, 4, 16, 4));
        // Shown as a player shows it, column 3 repeats column 2 and row 3
        // repeats row 2 (within the 4:2:0 rounding).
        let rgb = yuv420_to_rgb((&y, &u, &v), (4, 2, 2), 4, 4);
        let at = |x: usize, y: usize| &rgb[(y * 4 + x) * 3..][..3];
        for r in 0..4 {
            for k in 0..3 {
                let (a, b) = (at(3, r)[k] as i32, at(2, r)[k] as i32);
                assert!(
                    (a - b).abs() <= 24,
                    "row {r}: {:?} {:?}",
                    at(3, r),
                    at(2, r)
                );
            }
        }
    }

    #[test]
    fn sharp_conversion_beats_plain_subsampling_at_coloured_edges() {
        // A saturated red disc on grey, its edge at every phase.
        let (w, h) = (33u32, 31u32);
        let mut data = Vec::new();
        for y in 0..h {
            for x in 0..w {
                let d = ((x as f32 - 16.3).powi(2) + (y as f32 - 15.6).powi(2)).sqrt();
                data.extend_from_slice(if d < 9.0 {
                    &[230, 20, 10]
                } else {
                    &[90, 90, 90]
                });
            }
        }
        let img = Image8 {
            width: w,
            height: h,
            channels: 3,
            data,
        };
        let mse = |y: &[u8], u: &[u8], v: &[u8], pw: usize, ph: usize| {
            let rgb = yuv420_to_rgb((y, u, v), (pw, pw / 2, pw / 2), pw, ph);
            let mut e = 0.0f64;
            for py in 0..h as usize {
                for px in 0..w as usize {
                    for k in 0..3 {
                        let a = rgb[(py * pw + px) * 3 + k] as f64;
                        let b = img.data[(py * w as usize + px) * 3 + k] as f64;
                        e += (a - b).powi(2);
                    }
                }
            }
            e / (w * h * 3) as f64
        };
        let (y, u, v, pw, ph) = rgb_to_yuv420(&img);
        let sharp = mse(&y, &u, &v, pw, ph);
        // Plain: luma of each pixel, chroma the mean of each 2x2 block.
        let px = |x: usize, y: usize| {
            let i = (y.min(h as usize - 1) * w as usize + x.min(w as usize - 1)) * 3;
            [
                img.data[i] as f32,
                img.data[i + 1] as f32,
                img.data[i + 2] as f32,
            ]
        };
        let b = |v: f32| v.round().clamp(0.0, 255.0) as u8;
        let mut py = vec![0u8; pw * ph];
        for yy in 0..ph {
            for xx in 0..pw {
                let c = px(xx, yy);
                py[yy * pw + xx] =
                    b(16.0 + (65.481 * c[0] + 128.553 * c[1] + 24.966 * c[2]) / 255.0);
            }
        }
        let (mut pu, mut pv) = (Vec::new(), Vec::new());
        for cy in 0..ph / 2 {
            for cx in 0..pw / 2 {
                let mut m = [0.0f32; 3];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let c = px(cx * 2 + dx, cy * 2 + dy);
                    for k in 0..3 {
                        m[k] += c[k] / 4.0;
                    }
                }
                pu.push(b(
                    128.0 + (-37.797 * m[0] - 74.203 * m[1] + 112.0 * m[2]) / 255.0
                ));
                pv.push(b(
                    128.0 + (112.0 * m[0] - 93.786 * m[1] - 18.214 * m[2]) / 255.0
                ));
            }
        }
        let plain = mse(&py, &pu, &pv, pw, ph);
        println!("MSE sharp {sharp:.1}, plain {plain:.1}");
        // Measured: 111 against 160 (1.6 dB).
        assert!(sharp < plain * 0.8, "sharp {sharp}, plain {plain}");
    }

    #[test]
    fn quality_and_bitrate_parse() {
        assert_eq!(VideoQuality::qp(100), 10);
        assert_eq!(VideoQuality::qp(75), 20);
        assert_eq!(VideoQuality::qp(1), 51);
        assert_eq!(
            VideoQuality::parse_bitrate("2500k"),
            Some(VideoQuality::Bitrate(2_500_000))
        );
        assert_eq!(
            VideoQuality::parse_bitrate("4M"),
            Some(VideoQuality::Bitrate(4_000_000))
        );
        assert_eq!(VideoQuality::parse_bitrate("fast"), None);
        assert_eq!(VideoQuality::parse_bitrate("1k"), None);
    }
}
