//! The scene file as data: serde structs mirroring `docs/scene-format.md`
//! one to one. Nothing here loads files or knows about rendering; every value
//! that can be out of range keeps its span so that `validate` (and later
//! `build`) can point at it. Unknown keys and wrong types are rejected by serde
//! with the span of the offending key or value.
//!
//! One file per section of the file: `output`, `render`, `environment`
//! (with `[ground]` and `[ambient]`), `model`, `light`, `camera` (with
//! `[animation]`); `names` holds the file's spellings of the renderer's
//! values. `SceneDesc::parse` and the checks of `validate` are here.

use std::path::Path;

use serde::Deserialize;

use super::settings::{Background, VideoQuality};
use crate::error::{Error, Location};

mod camera;
mod environment;
mod light;
mod messages;
mod model;
mod names;
mod output;
mod render;
mod validate;

pub use camera::*;
pub use environment::*;
pub use light::*;
use messages::{in_words, source_excerpt};
pub use model::*;
pub use output::*;
pub use render::*;
pub use toml::Spanned;
use validate::*;

#[derive(Debug, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct SceneDesc {
    #[serde(default)]
    pub output: OutputDesc,
    #[serde(default)]
    pub render: RenderDesc,
    #[serde(default)]
    pub ambient: AmbientDesc,
    #[serde(default, rename = "model")]
    pub models: Vec<Spanned<ModelDesc>>,
    #[serde(default, rename = "light")]
    pub lights: Vec<Spanned<LightDesc>>,
    #[serde(default, rename = "camera")]
    pub cameras: Vec<Spanned<CameraDesc>>,
    #[serde(default)]
    pub animation: AnimationDesc,
    /// Version 2: image-based lighting.
    pub environment: Option<Spanned<EnvironmentDesc>>,
    /// Version 2: the shadow catcher.
    #[serde(default)]
    pub ground: GroundDesc,
}

// ---------------------------------------------------------------------------
// Parsing and validation.

impl SceneDesc {
    /// Parses scene text. `file` is only used to name locations in errors.
    pub fn parse(file: &Path, text: &str) -> Result<SceneDesc, Error> {
        let desc: SceneDesc = toml::from_str(text).map_err(|e| {
            let offset = e.span().map(|s| s.start).unwrap_or(0);
            Error::Scene {
                location: Location::from_offset(file, text, offset),
                message: format!(
                    "{}{}",
                    in_words(e.message().trim_end(), text, offset),
                    source_excerpt(text, offset)
                ),
            }
        })?;
        desc.validate(&Ctx { file, text })?;
        Ok(desc)
    }

    fn validate(&self, c: &Ctx) -> Result<(), Error> {
        if self.models.is_empty() {
            return Err(Error::SceneGlobal {
                file: c.file.to_path_buf(),
                message: "the scene has no [[model]]: at least one with a `path` is required"
                    .into(),
            });
        }
        let o = &self.output;
        c.int_range(&o.width, "output.width", 1, 16384)?;
        c.int_range(&o.height, "output.height", 1, 16384)?;
        c.int_range(&o.gif_delay_ms, "output.gif_delay_ms", 10, 655_350)?;
        if let Some(bg) = &o.background
            && let Background::Color(col) = bg.get_ref()
        {
            c.color(bg.span(), &col.to_array(), "output.background")?;
        }
        c.float_range(&o.background_blur, "output.background_blur", 0.0, 1.0)?;
        if let Some(bg) = &o.background
            && matches!(
                bg.get_ref(),
                Background::Environment | Background::Blurred(_)
            )
            && self.environment.is_none()
        {
            return Err(c.err(
                bg.span(),
                "output.background shows the environment: the scene needs an [environment]",
            ));
        }
        validate_video(c, o)?;
        if let Some(n) = &o.name
            && n.get_ref().trim().is_empty()
        {
            return Err(c.err(n.span(), "output.name must not be empty"));
        }
        let r = &self.render;
        if let Some(m) = &r.msaa
            && ![1, 2, 4, 8, 16].contains(m.get_ref())
        {
            return Err(c.err(
                m.span(),
                format!(
                    "render.msaa = {}: expected one of 1, 2, 4, 8, 16",
                    m.get_ref()
                ),
            ));
        }
        c.int_range(&r.ssaa, "render.ssaa", 1, 16)?;
        c.float_range(&r.point_size, "render.point_size", 0.5, 256.0)?;
        c.float_range(&r.line_width, "render.line_width", 0.25, 256.0)?;
        if let Some(k) = &r.ssaa {
            let side = get_i64(&o.width, 800).max(get_i64(&o.height, 800));
            if side * k.get_ref() > 16384 {
                return Err(c.err(
                    k.span(),
                    format!(
                        "render.ssaa = {}: the supersampled frame ({} px per side) may not exceed 16384",
                        k.get_ref(),
                        side * k.get_ref()
                    ),
                ));
            }
        }
        c.int_range(&r.max_anisotropy, "render.max_anisotropy", 1, 16)?;
        c.int_range(&r.shadow_map_size, "render.shadow_map_size", 16, 16384)?;
        if let Some(e) = &r.exposure
            && let Exposure::Stops(x) = e.get_ref()
            && !(x.is_finite() && (-64.0..=64.0).contains(x))
        {
            return Err(c.err(
                e.span(),
                format!("render.exposure = {x}: expected a number from -64 to 64, or \"auto\""),
            ));
        }
        if let Some(ao) = &r.ao {
            let ao = ao.get_ref();
            c.float_range(&ao.radius, "render.ao.radius", f32::MIN_POSITIVE, 1e9)?;
            c.int_range(&ao.samples, "render.ao.samples", 1, 4096)?;
        }
        if let Some(b) = &r.shadow_bias {
            let b = b.get_ref();
            for (v, key) in [
                (&b.constant, "render.shadow_bias.constant"),
                (&b.slope, "render.shadow_bias.slope"),
                (&b.normal, "render.shadow_bias.normal"),
            ] {
                c.float_range(v, key, 0.0, 1000.0)?;
            }
        }
        if let Some(a) = &self.ambient.color {
            c.color(a.span(), a.get_ref(), "ambient.color")?;
        }
        for m in &self.models {
            validate_model(c, m.get_ref())?;
        }
        for l in &self.lights {
            validate_light(c, l.get_ref())?;
        }
        for cam in &self.cameras {
            validate_camera(c, cam.get_ref())?;
        }
        if let Some(e) = &self.environment {
            validate_environment(c, e)?;
        }
        let a = &self.animation;
        c.int_range(&a.frames, "animation.frames", 1, 1_000_000)?;
        c.float_range(&a.fps, "animation.fps", 0.001, 1000.0)?;
        if let Some(t) = &a.turntable {
            let t = t.get_ref();
            c.finite(&t.degrees, "animation.turntable.degrees")?;
            c.direction(&t.axis, "animation.turntable.axis")?;
            c.float_range(&t.elevation, "animation.turntable.elevation", -89.0, 89.0)?;
        }
        Ok(())
    }
}

/// Validation context: turns spans into located errors.
pub struct Ctx<'a> {
    pub file: &'a Path,
    pub text: &'a str,
}

impl Ctx<'_> {
    pub fn err(&self, span: std::ops::Range<usize>, message: impl Into<String>) -> Error {
        Error::Scene {
            location: Location::from_offset(self.file, self.text, span.start),
            message: format!(
                "{}{}",
                message.into(),
                source_excerpt(self.text, span.start)
            ),
        }
    }

    pub fn location(&self, span: std::ops::Range<usize>) -> Location {
        Location::from_offset(self.file, self.text, span.start)
    }

    fn int_range(
        &self,
        v: &Option<Spanned<i64>>,
        key: &str,
        lo: i64,
        hi: i64,
    ) -> Result<(), Error> {
        if let Some(v) = v
            && !(lo..=hi).contains(v.get_ref())
        {
            return Err(self.err(
                v.span(),
                format!(
                    "{key} = {}: expected an integer from {lo} to {hi}",
                    v.get_ref()
                ),
            ));
        }
        Ok(())
    }

    fn float_range(
        &self,
        v: &Option<Spanned<f32>>,
        key: &str,
        lo: f32,
        hi: f32,
    ) -> Result<(), Error> {
        if let Some(v) = v {
            let x = *v.get_ref();
            if !(x.is_finite() && x >= lo && x <= hi) {
                return Err(self.err(
                    v.span(),
                    format!("{key} = {x}: expected a number from {lo} to {hi}"),
                ));
            }
        }
        Ok(())
    }

    fn finite(&self, v: &Option<Spanned<f32>>, key: &str) -> Result<(), Error> {
        self.float_range(v, key, f32::MIN, f32::MAX)
    }

    fn vec3(&self, v: &Option<Spanned<[f32; 3]>>, key: &str) -> Result<(), Error> {
        if let Some(v) = v
            && v.get_ref().iter().any(|x| !x.is_finite())
        {
            return Err(self.err(v.span(), format!("{key}: expected three finite numbers")));
        }
        Ok(())
    }

    fn direction(&self, v: &Option<Spanned<[f32; 3]>>, key: &str) -> Result<(), Error> {
        self.vec3(v, key)?;
        if let Some(v) = v
            && v.get_ref().iter().all(|x| *x == 0.0)
        {
            return Err(self.err(v.span(), format!("{key}: expected a non-zero direction")));
        }
        Ok(())
    }

    fn color(&self, span: std::ops::Range<usize>, c: &[f32; 3], key: &str) -> Result<(), Error> {
        if c.iter().any(|x| !x.is_finite() || *x < 0.0) {
            return Err(self.err(
                span,
                format!("{key}: expected three finite, non-negative linear RGB values"),
            ));
        }
        Ok(())
    }
}

/// The offending line of the scene, printed under a message, compiler style.
#[cfg(test)]
mod tests {
    use super::*;

    fn parse(t: &str) -> Result<SceneDesc, Error> {
        SceneDesc::parse(Path::new("t.toml"), t)
    }

    #[test]
    fn sizes_parse() {
        assert_eq!(parse_size("1048576"), Ok(1 << 20));
        assert_eq!(parse_size("512M"), Ok(512 << 20));
        assert_eq!(parse_size("512MiB"), Ok(512 << 20));
        assert_eq!(parse_size("1.5G"), Ok(3 << 29));
        assert_eq!(parse_size("2 gb"), Ok(2 << 30));
        assert!(parse_size("lots").is_err());
        assert!(parse_size("5X").is_err());
        assert!(parse_size("0").is_err());
        let m = "[[model]]\npath = \"a.obj\"\n";
        let s = parse(&format!("{m}[render]\nmax_memory = \"64M\"\n")).unwrap();
        assert_eq!(s.render.max_memory.map(|m| m.get_ref().0), Some(64 << 20));
        let e = parse(&format!("{m}[render]\nmax_memory = \"a lot\"\n")).unwrap_err();
        assert!(e.to_string().contains("is not a size"), "{e}");
    }

    #[test]
    fn smallest_scene_parses() {
        let d = parse("[[model]]\npath = \"a.obj\"\n").unwrap();
        assert_eq!(d.models.len(), 1);
        assert!(d.cameras.is_empty());
    }

    #[test]
    fn full_example_of_the_contract_parses() {
        let d = parse(include_str!("../../../tests/data/full_example.toml")).unwrap();
        assert_eq!(d.lights.len(), 3);
        assert_eq!(
            d.models[0].get_ref().materials.len(),
            1,
            "per-material override table"
        );
    }

    #[test]
    fn unknown_key_names_line_and_column() {
        let e = parse("[[model]]\npath = \"a.obj\"\n[render]\nmsa = 4\n").unwrap_err();
        let s = e.to_string();
        assert!(s.starts_with("t.toml:4:1:"), "{s}");
        assert!(s.contains("msa"), "{s}");
    }

    #[test]
    fn wrong_type_and_range_are_located() {
        let e = parse("[[model]]\npath = \"a.obj\"\n[output]\nwidth = \"big\"\n").unwrap_err();
        assert!(e.to_string().starts_with("t.toml:4:9:"), "{e}");
        let e = parse("[[model]]\npath = \"a.obj\"\n[render]\nmsaa = 3\n").unwrap_err();
        assert!(
            e.to_string().contains("expected one of 1, 2, 4, 8, 16"),
            "{e}"
        );
        assert!(e.to_string().starts_with("t.toml:4:8:"), "{e}");
        let e = parse("[[model]]\npath = \"a.obj\"\n[render]\nshading = \"toon\"\n").unwrap_err();
        assert!(e.to_string().contains("blinn-phong"), "{e}");
    }

    #[test]
    fn missing_model_is_an_error() {
        let e = parse("[output]\nwidth = 10\n").unwrap_err();
        assert!(e.to_string().contains("[[model]]"));
        assert_eq!(e.exit_code(), 2);
    }

    #[test]
    fn scale_and_background_accept_both_spellings() {
        let d = parse(
            "[[model]]\npath = \"a.obj\"\nscale = 2\n[output]\nbackground = \"transparent\"\n",
        )
        .unwrap();
        assert_eq!(
            d.models[0].get_ref().scale.as_ref().unwrap().get_ref().0,
            [2.0; 3]
        );
        assert_eq!(
            *d.output.background.as_ref().unwrap().get_ref(),
            Background::Transparent
        );
        let d = parse("[[model]]\npath = \"a.obj\"\nscale = [1, 2, 3.5]\n").unwrap();
        assert_eq!(
            d.models[0].get_ref().scale.as_ref().unwrap().get_ref().0,
            [1.0, 2.0, 3.5]
        );
        assert!(parse("[[model]]\npath = \"a.obj\"\nscale = [1, 2]\n").is_err());
        assert!(parse("[[model]]\npath = \"a.obj\"\nscale = 0\n").is_err());
    }

    #[test]
    fn spot_cone_must_be_ordered() {
        let e = parse(
            "[[model]]\npath = \"a.obj\"\n[[light]]\nkind = \"spot\"\ninner_angle = 40\nouter_angle = 30\n",
        )
        .unwrap_err();
        assert!(e.to_string().contains("inner_angle"), "{e}");
    }

    #[test]
    fn a_light_range_is_a_positive_distance_of_a_point_or_spot() {
        let light =
            |body: &str| parse(&format!("[[model]]\npath = \"a.obj\"\n[[light]]\n{body}\n"));
        let d = light("kind = \"spot\"\nrange = 2.5").unwrap();
        let r = d.lights[0].get_ref().range.as_ref().map(|r| *r.get_ref());
        assert_eq!(r, Some(2.5));
        assert!(light("range = 3").is_ok(), "a point light by default");
        for (body, says) in [
            ("range = 0", "light.range = 0"),
            ("range = -1", "light.range = -1"),
            ("range = inf", "light.range = inf"),
            ("kind = \"directional\"\nrange = 2", "not directional"),
        ] {
            let e = light(body).unwrap_err().to_string();
            // The file, and the line of `range`.
            let line = format!("t.toml:{}:", 3 + body.lines().count());
            assert!(e.contains(says) && e.starts_with(&line), "{body}: {e}");
        }
    }
}
