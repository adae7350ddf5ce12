//! `[render]`, `[output]` and `[ambient]` to `RenderSettings` and
//! `OutputSettings`: the file's values mapped to the renderer's types, the
//! defaults filled in (each named once, here), and the keys that are valid
//! but do nothing with the rest of the scene reported as warnings.

use std::path::{Path, PathBuf};

use glam::Vec3;

use super::get;
use crate::error::Error;
use crate::scene::check_pattern;
use crate::scene::desc::{self, Ctx, SceneDesc};
use crate::scene::settings::{
    AoMethod, AoSettings, Background, OutputSettings, RenderSettings, ShadowBias, ShadowMethod,
    TextureFilter, Tonemap, VideoQuality, check_video_size,
};

/// An optional key's value, or the renderer's default for it.
fn pick<T: Copy + Default>(v: &Option<desc::Spanned<T>>) -> T {
    v.as_ref().map(|v| *v.get_ref()).unwrap_or_default()
}

/// The default look (version 3): every scene without `[ambient]` and
/// without an `[environment]` that names a `path` or another `preset` is
/// lit by the built-in studio (its `[environment]` keys, such as
/// `rotation`, modify it), over its blurred background, with a ground
/// shadow and PBR Neutral, each unless its own key is set. `[[light]]`s
/// add to it.
pub(super) fn default_look(d: &SceneDesc) -> bool {
    d.ambient.color.is_none()
        && d.environment.as_ref().is_none_or(|e| {
            let e = e.get_ref();
            e.path.is_none()
                && e.preset
                    .as_ref()
                    .is_none_or(|p| *p.get_ref() == desc::EnvPreset::Studio)
        })
}

/// `[render]`, `output.width/height/background` and `[ambient]`, with the
/// defaults of the default look when `default_look`.
pub(super) fn render(d: &SceneDesc, default_look: bool) -> RenderSettings {
    let (r, o) = (&d.render, &d.output);
    let lit_by_environment = d.environment.is_some() || default_look;
    let background = if default_look {
        Background::Blurred(0.5)
    } else {
        Background::Color(Vec3::ZERO)
    };
    RenderSettings {
        width: get(&o.width, 800) as u32,
        height: get(&o.height, 800) as u32,
        shading: pick(&r.shading),
        texture_filter: pick(&r.texture_filter),
        max_anisotropy: get(&r.max_anisotropy, 16) as f32,
        specular_aa: get(&r.specular_aa, true),
        address: pick(&r.address),
        cull: pick(&r.cull),
        max_memory: r.max_memory.as_ref().map(|m| m.get_ref().0),
        sandbox: get(&r.sandbox, false),
        point_size: get(&r.point_size, 4.0),
        line_width: get(&r.line_width, 1.5),
        depth: pick(&r.depth),
        // The default look keeps the studio's highlights: PBR Neutral
        // leaves colours under 0.76 as they are and rolls off above.
        tonemap: match &r.tonemap {
            Some(t) => *t.get_ref(),
            None if default_look => Tonemap::PbrNeutral,
            None => Tonemap::default(),
        },
        exposure: match r.exposure.as_ref().map(|e| *e.get_ref()) {
            Some(desc::Exposure::Stops(x)) => x,
            _ => 0.0,
        },
        auto_exposure: matches!(
            r.exposure.as_ref().map(|e| *e.get_ref()),
            Some(desc::Exposure::Auto)
        ),
        background: match get(&o.background, background) {
            Background::Blurred(_) => Background::Blurred(get(&o.background_blur, 0.5)),
            b => b,
        },
        // With an environment lighting the scene, no ambient by default.
        ambient: Vec3::from(get(
            &d.ambient.color,
            if lit_by_environment {
                [0.0; 3]
            } else {
                [0.03; 3]
            },
        )),
        shadows: shadow_method(r),
        shadow_map_size: get(&r.shadow_map_size, 2048) as u32,
        shadow_bias: shadow_bias(r),
        ao: ao_settings(r),
        msaa: get(&r.msaa, 1) as u32,
        ssaa: get(&r.ssaa, 1) as u32,
    }
}

/// `[output]`: where the files go and what they are called. `out_dir`
/// (`--out`) wins over `output.dir`; without either, `out/<scene stem>`.
pub(super) fn output(
    d: &SceneDesc,
    ctx: &Ctx,
    settings: &RenderSettings,
    scene_dir: &Path,
    stem: &str,
    out_dir: Option<&Path>,
) -> Result<OutputSettings, Error> {
    let o = &d.output;
    if let Some(v) = &o.ao
        && *v.get_ref()
        && settings.ao.method == AoMethod::Off
    {
        return Err(ctx.err(
            v.span(),
            "output.ao = true needs render.ao with method = \"ssao\" or \"raytraced\"",
        ));
    }
    let name = get(&o.name, "{camera}_{frame:04}".to_string());
    if let Err(msg) = check_pattern(&name) {
        let span = o.name.as_ref().map(|n| n.span()).unwrap_or(0..0);
        return Err(ctx.err(span, format!("output.name: {msg}")));
    }
    if let (Some(g), Some(c)) = (&o.gif, &o.color)
        && !*c.get_ref()
    {
        return Err(ctx.err(
            g.span(),
            "output.gif is assembled from the color frames: it needs output.color = true",
        ));
    }
    if let Some(v) = &o.video {
        if settings.background == Background::Transparent {
            return Err(ctx.err(
                v.span(),
                "output.video cannot hold a transparent background (H.264 has no alpha): \
                 give output.background a colour, or drop output.video",
            ));
        }
        if let Err(m) = check_video_size(settings.width, settings.height) {
            return Err(ctx.err(v.span(), format!("output.video: {m}")));
        }
    }
    let video_quality = match o.video_quality.as_ref().map(|q| q.get_ref()) {
        None => VideoQuality::default(),
        Some(desc::VideoQualityDesc::Number(n)) => VideoQuality::Quality((*n).clamp(1, 100) as u8),
        Some(desc::VideoQualityDesc::Text(t)) => VideoQuality::parse_bitrate(t).unwrap_or_default(),
    };
    // The video's rate: `output.video_fps`, else the animation's, else
    // the GIF's delay.
    let video_fps = match (&o.video_fps, &d.animation.fps) {
        (Some(f), _) | (None, Some(f)) => *f.get_ref() as f64,
        (None, None) => 1000.0 / get(&o.gif_delay_ms, 40) as f64,
    };
    for (key, v) in [("output.gif", &o.gif), ("output.video", &o.video)] {
        if let Some(v) = v
            && let Err(m) = check_output_file(v.get_ref())
        {
            return Err(ctx.err(v.span(), format!("{key} = {:?}: {m}", v.get_ref())));
        }
    }
    let dir = match (out_dir, &o.dir) {
        (Some(out), _) => out.to_path_buf(),
        (None, Some(dir)) => scene_dir.join(dir.get_ref()),
        (None, None) => PathBuf::from("out").join(stem),
    };
    if let Ok(m) = std::fs::metadata(&dir)
        && !m.is_dir()
    {
        let what = format!(
            "the output folder {} is {}, not a folder",
            dir.display(),
            crate::files::kind(&m)
        );
        return Err(match (out_dir, &o.dir) {
            (None, Some(d)) => ctx.err(d.span(), format!("output.dir: {what}")),
            _ => Error::Argument(format!("--out: {what}")),
        });
    }
    Ok(OutputSettings {
        dir,
        name,
        color: get(&o.color, true),
        depth: get(&o.depth, false),
        ao: get(&o.ao, false),
        gif: o.gif.as_ref().map(|g| g.get_ref().clone()),
        gif_delay_ms: gif_delay_ms(d),
        gif_dither: pick(&o.gif_dither),
        video: o.video.as_ref().map(|v| v.get_ref().clone()),
        video_fps,
        video_quality,
        normal: get(&o.normal, false),
        albedo: get(&o.albedo, false),
        position: get(&o.position, false),
        id: get(&o.id, false),
    })
}

/// `output.gif_delay_ms`, else one frame of `animation.fps` (a GIF stores
/// hundredths of a second: 24 fps gives 40 ms, 12 fps 80 ms), else 40 ms.
fn gif_delay_ms(d: &SceneDesc) -> u32 {
    match (&d.output.gif_delay_ms, &d.animation.fps) {
        (Some(ms), _) => *ms.get_ref() as u32,
        (None, Some(fps)) => {
            let ms = 1000.0 / *fps.get_ref() as f64;
            ((ms / 10.0).round() * 10.0).clamp(10.0, 655_350.0) as u32
        }
        (None, None) => 40,
    }
}

/// `output.gif` and `output.video` are files inside the output folder:
/// a relative path to a file, without `..`.
fn check_output_file(name: &str) -> Result<(), String> {
    let p = Path::new(name);
    if name.trim().is_empty() || name.contains('\0') {
        return Err("expected a file name, such as \"turntable.gif\"".into());
    }
    if name.ends_with('/') || name.ends_with('\\') || p.file_name().is_none() {
        return Err("names a folder, not a file".into());
    }
    for c in p.components() {
        match c {
            std::path::Component::Normal(_) | std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                return Err("`..` would write outside the output folder".into());
            }
            _ => return Err("an absolute path would write outside the output folder".into()),
        }
    }
    if name.contains('\\') {
        return Err("`\\` is not a path separator here; use `/`".into());
    }
    Ok(())
}

fn shadow_bias(r: &desc::RenderDesc) -> ShadowBias {
    let d = ShadowBias::default();
    match &r.shadow_bias {
        Some(b) => {
            let b = b.get_ref();
            ShadowBias {
                constant: get(&b.constant, d.constant),
                slope: get(&b.slope, d.slope),
                normal: get(&b.normal, d.normal),
            }
        }
        None => d,
    }
}

/// `render.shadows`, or without it: pcf when the scene sets a shadow-map
/// key (it asked for maps), otherwise the default (raytraced).
fn shadow_method(r: &desc::RenderDesc) -> ShadowMethod {
    match &r.shadows {
        Some(m) => *m.get_ref(),
        None if r.shadow_map_size.is_some() || r.shadow_bias.is_some() => ShadowMethod::Pcf,
        None => ShadowMethod::default(),
    }
}

/// `render.ao`: 64 rays a pixel ray-traced, 16 depth reads a pixel GTAO.
fn ao_settings(r: &desc::RenderDesc) -> AoSettings {
    let (method, radius, samples) = match &r.ao {
        Some(a) => {
            let a = a.get_ref();
            (
                pick(&a.method),
                a.radius.as_ref().map(|r| *r.get_ref()),
                a.samples.as_ref().map(|s| *s.get_ref() as u32),
            )
        }
        None => (AoMethod::Off, None, None),
    };
    let default_samples = if method == AoMethod::Raytraced {
        64
    } else {
        16
    };
    AoSettings {
        method,
        radius,
        samples: samples.unwrap_or(default_samples),
    }
}

/// Keys that are valid but do nothing with the rest of the scene: said as
/// warnings naming where they are, never silently dropped.
pub(super) fn no_effect_warnings(d: &SceneDesc, ctx: &Ctx, s: &RenderSettings) -> Vec<String> {
    let (r, o) = (&d.render, &d.output);
    let mut out = Vec::new();
    let mut warn = |span: Option<std::ops::Range<usize>>, what: &str| {
        if let Some(span) = span {
            out.push(format!("{}: {what}", ctx.location(span)));
        }
    };
    if !matches!(s.shadows, ShadowMethod::Hard | ShadowMethod::Pcf) {
        let why = "has no effect: render.shadows is not hard or pcf";
        warn(
            r.shadow_map_size.as_ref().map(|v| v.span()),
            &format!("render.shadow_map_size {why}"),
        );
        warn(
            r.shadow_bias.as_ref().map(|v| v.span()),
            &format!("render.shadow_bias {why}"),
        );
    }
    if s.texture_filter != TextureFilter::Anisotropic {
        warn(
            r.max_anisotropy.as_ref().map(|v| v.span()),
            "render.max_anisotropy has no effect: render.texture_filter is not anisotropic",
        );
    }
    if s.specular_aa
        && !matches!(
            s.texture_filter,
            TextureFilter::Trilinear | TextureFilter::Anisotropic
        )
    {
        // Without footprints there is no pixel's step to look up.
        warn(
            r.specular_aa.as_ref().map(|v| v.span()),
            "render.specular_aa has no effect: render.texture_filter is not trilinear or anisotropic",
        );
    }
    if s.ao.method == AoMethod::Off
        && let Some(ao) = &r.ao
        && (ao.get_ref().radius.is_some() || ao.get_ref().samples.is_some())
    {
        warn(
            Some(ao.span()),
            "render.ao radius/samples have no effect without a method (ssao or raytraced)",
        );
    }
    if !matches!(s.background, Background::Blurred(_)) {
        warn(
            o.background_blur.as_ref().map(|v| v.span()),
            "output.background_blur has no effect: output.background is not \"blurred\"",
        );
    }
    if let Some(e) = &d.environment {
        let e = e.get_ref();
        if !matches!(
            e.method.as_ref().map(|m| *m.get_ref()),
            Some(desc::EnvMethodName::Sampled)
        ) {
            warn(
                e.samples.as_ref().map(|v| v.span()),
                "environment.samples has no effect: environment.method is not \"sampled\"",
            );
        } else {
            warn(
                e.prefilter_size.as_ref().map(|v| v.span()),
                "environment.prefilter_size has no effect: environment.method is \"sampled\"",
            );
            warn(
                e.emitters.as_ref().map(|v| v.span()),
                "environment.emitters has no effect: environment.method \"sampled\" lights with every emissive surface",
            );
            warn(
                e.reflections.as_ref().map(|v| v.span()),
                "environment.reflections has no effect: environment.method \"sampled\" traces every reflection",
            );
        }
    }
    for c in &d.cameras {
        let c = c.get_ref();
        if c.eye.is_some() {
            let why = "has no effect: the camera gives its eye (only fitted cameras take it)";
            warn(
                c.elevation.as_ref().map(|v| v.span()),
                &format!("camera.elevation {why}"),
            );
            warn(
                c.azimuth.as_ref().map(|v| v.span()),
                &format!("camera.azimuth {why}"),
            );
        }
    }
    if o.video.is_none() {
        let why = "has no effect without output.video";
        warn(
            o.video_fps.as_ref().map(|v| v.span()),
            &format!("output.video_fps {why}"),
        );
        warn(
            o.video_quality.as_ref().map(|v| v.span()),
            &format!("output.video_quality {why}"),
        );
    }
    if o.gif.is_none() {
        let why = "has no effect without output.gif";
        warn(
            o.gif_delay_ms.as_ref().map(|v| v.span()),
            &format!("output.gif_delay_ms {why}"),
        );
        warn(
            o.gif_dither.as_ref().map(|v| v.span()),
            &format!("output.gif_dither {why}"),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::settings::{AddressMode, CullMode, DepthMode, GifDither, ShadingMode};

    fn parse(text: &str) -> SceneDesc {
        SceneDesc::parse(Path::new("s.toml"), text).unwrap()
    }

    #[test]
    fn defaults_when_the_file_says_nothing() {
        let d = parse("[[model]]\npath = \"m.obj\"\n");
        let s = render(&d, default_look(&d));
        assert_eq!((s.width, s.height, s.msaa, s.ssaa), (800, 800, 1, 1));
        assert_eq!(s.shading, ShadingMode::Auto);
        assert_eq!(s.texture_filter, TextureFilter::Anisotropic);
        assert_eq!(s.max_anisotropy, 16.0);
        assert_eq!(s.address, AddressMode::Repeat);
        assert_eq!(s.cull, CullMode::Auto);
        assert_eq!(s.depth, DepthMode::ReverseZ);
        assert_eq!(s.tonemap, Tonemap::PbrNeutral);
        assert_eq!(s.exposure, 0.0);
        // No light and no environment: the default look (studio, blurred
        // background, no ambient).
        assert!(default_look(&d));
        assert_eq!(s.background, Background::Blurred(0.5));
        assert_eq!(s.ambient, Vec3::ZERO);
        assert_eq!(s.shadows, ShadowMethod::Raytraced);
        assert_eq!(s.shadow_map_size, 2048);
        assert_eq!(s.shadow_bias, ShadowBias::default());
        assert_eq!(s.ao.method, AoMethod::Off);
        // A light adds to the look (version 3).
        let lit = parse("[[model]]\npath = \"m.obj\"\n[[light]]\n");
        assert!(default_look(&lit));
        // [environment] keys without a path or another preset modify the
        // studio; the look stays.
        let turned = parse("[[model]]\npath = \"m.obj\"\n[environment]\nrotation = 90.0\n");
        assert!(default_look(&turned));
        let neutral = parse("[[model]]\npath = \"m.obj\"\n[environment]\npreset = \"neutral\"\n");
        assert!(!default_look(&neutral));
        // [ambient]: version 1's defaults.
        let v1 = parse(
            "[[model]]\npath = \"m.obj\"\n[[light]]\n[ambient]\ncolor = [0.03, 0.03, 0.03]\n",
        );
        assert!(!default_look(&v1));
        assert_eq!(
            render(&v1, default_look(&v1)).background,
            Background::Color(Vec3::ZERO)
        );
        assert_eq!(render(&v1, default_look(&v1)).ambient, Vec3::splat(0.03));
        assert_eq!(render(&v1, default_look(&v1)).tonemap, Tonemap::Clamp);
        let ctx = Ctx {
            file: Path::new("dir/s.toml"),
            text: "",
        };
        let o = output(&d, &ctx, &s, Path::new("dir"), "s", None).unwrap();
        assert_eq!(o.dir, PathBuf::from("out/s"));
        assert_eq!(o.name, "{camera}_{frame:04}");
        assert!(o.color && !o.depth && !o.ao && o.gif.is_none());
        assert_eq!((o.gif_delay_ms, o.gif_dither), (40, GifDither::None));
    }

    #[test]
    fn the_gif_delay_follows_the_animations_rate() {
        for (text, ms) in [
            ("[animation]\nfps = 12\n", 80),
            ("[animation]\nfps = 24\n", 40),
            ("[animation]\nfps = 30\n", 30),
            ("[animation]\nfps = 12\n[output]\ngif_delay_ms = 100\n", 100),
            ("", 40),
        ] {
            let d = parse(&format!("[[model]]\npath = \"m.obj\"\n{text}"));
            assert_eq!(gif_delay_ms(&d), ms, "{text}");
        }
    }

    #[test]
    fn file_values_map_to_the_renderers_types() {
        let d = parse(
            "[[model]]\npath = \"m.obj\"\n[render]\nshading = \"blinn-phong\"\n\
             texture_filter = \"trilinear\"\ncull = \"none\"\ndepth = \"standard\"\n\
             tonemap = \"aces\"\nao = { method = \"ssao\" }\n\
             [output]\nbackground = \"transparent\"\ngif = \"a.gif\"\ngif_dither = \"floyd-steinberg\"\n",
        );
        let s = render(&d, default_look(&d));
        assert_eq!(s.shading, ShadingMode::BlinnPhong);
        assert_eq!(s.texture_filter, TextureFilter::Trilinear);
        assert_eq!(s.cull, CullMode::None);
        assert_eq!(s.depth, DepthMode::Standard);
        assert_eq!(s.tonemap, Tonemap::Aces);
        assert_eq!(s.background, Background::Transparent);
        // The file's `ssao` is GTAO, 16 depth reads a pixel by default.
        assert_eq!((s.ao.method, s.ao.samples), (AoMethod::Gtao, 16));
        let ctx = Ctx {
            file: Path::new("s.toml"),
            text: "",
        };
        let o = output(&d, &ctx, &s, Path::new(""), "s", Some(Path::new("o"))).unwrap();
        assert_eq!(o.dir, PathBuf::from("o"));
        assert_eq!(o.gif_dither, GifDither::FloydSteinberg);
    }

    #[test]
    fn a_shadow_map_key_without_a_method_selects_pcf() {
        let d = parse("[[model]]\npath = \"m.obj\"\n[render]\nshadow_map_size = 1024\n");
        assert_eq!(render(&d, default_look(&d)).shadows, ShadowMethod::Pcf);
        let d = parse("[[model]]\npath = \"m.obj\"\n[render]\nao = { method = \"raytraced\" }\n");
        assert_eq!(render(&d, default_look(&d)).ao.samples, 64);
    }
}
