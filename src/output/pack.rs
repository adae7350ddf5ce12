//! A frame's files: where they go (`OutputFiles`, named by the run's
//! plan) and its buffers packed for them (`FileToWrite`): the display image
//! as PNG, depth and AO as one-channel EXRs, the data passes (normal,
//! albedo, position, ids) as EXR layers of several channels.

use std::path::PathBuf;

use super::Image8;
use crate::error::Error;
use crate::render::{AovPixel, Frame};

/// The files of one frame of one camera (None: the scene does not ask).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OutputFiles {
    /// `<name>.png`.
    pub color: Option<PathBuf>,
    /// `<name>_depth.exr`, channel `Z`.
    pub depth: Option<PathBuf>,
    /// `<name>_ao.exr`, channel `AO`.
    pub ao: Option<PathBuf>,
    /// `<name>_normal.exr`, channels `N.X N.Y N.Z`.
    pub normal: Option<PathBuf>,
    /// `<name>_albedo.exr`, channels `albedo.R albedo.G albedo.B`.
    pub albedo: Option<PathBuf>,
    /// `<name>_position.exr`, channels `P.X P.Y P.Z`.
    pub position: Option<PathBuf>,
    /// `<name>_id.exr`, UINT channels `object_id` and `material_id`.
    pub id: Option<PathBuf>,
}

impl OutputFiles {
    /// The files, color first.
    pub fn all(&self) -> Vec<PathBuf> {
        [
            &self.color,
            &self.depth,
            &self.ao,
            &self.normal,
            &self.albedo,
            &self.position,
            &self.id,
        ]
        .into_iter()
        .flatten()
        .cloned()
        .collect()
    }
}

/// One file of a frame, ready to write: its buffers are the frame's
/// own, copied out of the renderer's (which renders the next frame into
/// them while this one is written).
pub enum FileToWrite {
    /// Path, display image.
    Png(PathBuf, Image8),
    /// Path, width, height, channel name, values.
    Exr(PathBuf, u32, u32, &'static str, Vec<f32>),
    /// Path, width, height, channels.
    ExrChannels(PathBuf, u32, u32, Vec<(&'static str, super::exr::Samples)>),
}

impl FileToWrite {
    /// Where it goes.
    pub fn path(&self) -> &std::path::Path {
        match self {
            FileToWrite::Png(p, _) | FileToWrite::Exr(p, ..) | FileToWrite::ExrChannels(p, ..) => p,
        }
    }

    /// Writes it (atomically), handing its buffers to the encoder.
    pub fn write(self) -> Result<(), Error> {
        match self {
            FileToWrite::Png(p, img) => super::png::write(&p, &img),
            FileToWrite::Exr(p, w, h, channel, values) => {
                super::exr::write_channel(&p, w, h, channel, values)
            }
            FileToWrite::ExrChannels(p, w, h, channels) => {
                super::exr::write_channels(&p, w, h, channels)
            }
        }
    }
}

/// A frame's files from its buffers and its display image (made where
/// the plan writes a colour file or `color` asks for it), as the plan
/// names them, and (with `color`) the display image for a video.
pub fn pack(
    frame: &Frame,
    image: Option<Image8>,
    files: OutputFiles,
    color: bool,
) -> (Vec<FileToWrite>, Option<Image8>) {
    let (width, height) = (frame.width, frame.height);
    let mut out = Vec::new();
    let mut image = image;
    // (`image.take()` runs only where a colour file is written.)
    if let Some(p) = files.color
        && let Some(img) = image.take()
    {
        if color {
            image = Some(img.clone());
        }
        out.push(FileToWrite::Png(p, img));
    }
    if let Some(p) = files.depth {
        out.push(FileToWrite::Exr(p, width, height, "Z", frame.depth.clone()));
    }
    if let Some(p) = files.ao {
        let ao = if frame.ao.is_empty() {
            vec![1.0; frame.depth.len()]
        } else {
            frame.ao.clone()
        };
        out.push(FileToWrite::Exr(p, width, height, "AO", ao));
    }
    let aov = &frame.aov;
    let vec3 = |names: [&'static str; 3], get: fn(&AovPixel) -> glam::Vec3| {
        (0..3)
            .map(|k| {
                let v = aov.iter().map(|a| get(a)[k]).collect();
                (names[k], super::exr::Samples::F32(v))
            })
            .collect::<Vec<_>>()
    };
    if !aov.is_empty() {
        if let Some(p) = files.normal {
            let c = vec3(["N.X", "N.Y", "N.Z"], |a| a.normal);
            out.push(FileToWrite::ExrChannels(p, width, height, c));
        }
        if let Some(p) = files.albedo {
            let c = vec3(["albedo.R", "albedo.G", "albedo.B"], |a| a.albedo);
            out.push(FileToWrite::ExrChannels(p, width, height, c));
        }
        if let Some(p) = files.position {
            let c = vec3(["P.X", "P.Y", "P.Z"], |a| a.position);
            out.push(FileToWrite::ExrChannels(p, width, height, c));
        }
        if let Some(p) = files.id {
            let ids =
                |get: fn(&AovPixel) -> u32| super::exr::Samples::U32(aov.iter().map(get).collect());
            let c = vec![
                ("object_id", ids(|a| a.object)),
                ("material_id", ids(|a| a.material)),
            ];
            out.push(FileToWrite::ExrChannels(p, width, height, c));
        }
    }
    (out, image)
}
