//! The checks of each section that serde's types do not make: value
//! ranges, keys that exclude each other, camera keys in order, a video
//! output's settings. Each error names the key's line and column.

use super::*;

/// `output.video`: an `.mp4` name, a frame rate and a quality in range.
pub(super) fn validate_video(c: &Ctx, o: &OutputDesc) -> Result<(), Error> {
    if let Some(v) = &o.video {
        let name = v.get_ref();
        let ext = Path::new(name)
            .extension()
            .and_then(|e| e.to_str())
            .map(|e| e.to_ascii_lowercase());
        if ext.as_deref() != Some("mp4") {
            return Err(c.err(
                v.span(),
                format!(
                    "output.video = \"{name}\": expected a file name ending in .mp4 (H.264 in MP4)"
                ),
            ));
        }
    }
    c.float_range(&o.video_fps, "output.video_fps", 0.1, 240.0)?;
    if let Some(q) = &o.video_quality {
        match q.get_ref() {
            VideoQualityDesc::Number(n) if !(1..=100).contains(n) => {
                return Err(c.err(
                    q.span(),
                    format!("output.video_quality = {n}: expected a quality from 1 to 100, or a bitrate like \"2500k\""),
                ));
            }
            VideoQualityDesc::Text(t) if VideoQuality::parse_bitrate(t).is_none() => {
                return Err(c.err(
                    q.span(),
                    format!("output.video_quality = \"{t}\": expected a bitrate from 10k to 200M such as \"2500k\" or \"4M\", or a quality from 1 to 100"),
                ));
            }
            _ => {}
        }
    }
    Ok(())
}

pub(super) fn get_i64(v: &Option<Spanned<i64>>, default: i64) -> i64 {
    v.as_ref().map(|v| *v.get_ref()).unwrap_or(default)
}

pub(super) fn validate_environment(c: &Ctx, e: &Spanned<EnvironmentDesc>) -> Result<(), Error> {
    let e = e.get_ref();
    match (&e.path, &e.preset) {
        (Some(p), None) if p.get_ref().trim().is_empty() => {
            return Err(c.err(p.span(), "environment.path must not be empty"));
        }
        (Some(_), Some(p)) => {
            return Err(c.err(p.span(), "environment: give `path` or `preset`, not both"));
        }
        // Version 3: neither modifies the studio (its rotation, intensity).
        _ => {}
    }
    c.float_range(&e.intensity, "environment.intensity", 0.0, 1e9)?;
    c.finite(&e.rotation, "environment.rotation")?;
    c.int_range(&e.samples, "environment.samples", 1, 65536)?;
    c.int_range(&e.bounces, "environment.bounces", 0, 1)?;
    c.int_range(&e.prefilter_size, "environment.prefilter_size", 8, 2048)?;
    c.int_range(&e.lights, "environment.lights", 0, 16)?;
    c.int_range(&e.emitters, "environment.emitters", 0, 16)?;
    Ok(())
}

pub(super) fn validate_model(c: &Ctx, m: &ModelDesc) -> Result<(), Error> {
    if m.path.get_ref().trim().is_empty() {
        return Err(c.err(m.path.span(), "model.path must not be empty"));
    }
    c.vec3(&m.translate, "model.translate")?;
    c.vec3(&m.rotate, "model.rotate")?;
    if let Some(s) = &m.scale
        && s.get_ref().0.iter().any(|v| !v.is_finite() || *v == 0.0)
    {
        return Err(c.err(
            s.span(),
            "model.scale must be finite and non-zero (a number or [x, y, z])",
        ));
    }
    if let Some(o) = &m.material {
        validate_override(c, o.get_ref())?;
    }
    for o in m.materials.values() {
        validate_override(c, o.get_ref())?;
    }
    Ok(())
}

fn validate_override(c: &Ctx, o: &MaterialOverride) -> Result<(), Error> {
    for (v, key) in [(&o.ka, "ka"), (&o.kd, "kd"), (&o.ks, "ks"), (&o.ke, "ke")] {
        if let Some(v) = v {
            c.color(v.span(), v.get_ref(), key)?;
        }
    }
    c.float_range(&o.ns, "ns", 0.0, 1e6)?;
    c.float_range(&o.ni, "ni", 0.0, 100.0)?;
    c.float_range(&o.d, "d", 0.0, 1.0)?;
    c.int_range(&o.illum, "illum", 0, 10)?;
    c.finite(&o.bump_scale, "bump_scale")?;
    c.float_range(&o.alpha_cutoff, "alpha_cutoff", 0.0, 1.0)?;
    c.float_range(&o.metallic, "metallic", 0.0, 1.0)?;
    c.float_range(&o.roughness, "roughness", 0.0, 1.0)?;
    c.finite(&o.disp_scale, "disp_scale")?;
    Ok(())
}

pub(super) fn validate_light(c: &Ctx, l: &LightDesc) -> Result<(), Error> {
    c.vec3(&l.position, "light.position")?;
    c.direction(&l.direction, "light.direction")?;
    c.float_range(&l.intensity, "light.intensity", 0.0, 1e30)?;
    c.float_range(&l.irradiance, "light.irradiance", 0.0, 1e30)?;
    if let Some(col) = &l.color {
        c.color(col.span(), col.get_ref(), "light.color")?;
    }
    c.float_range(&l.inner_angle, "light.inner_angle", 0.0, 90.0)?;
    c.float_range(&l.outer_angle, "light.outer_angle", 0.0, 90.0)?;
    if let Some(r) = &l.range {
        let x = *r.get_ref();
        if l.kind.as_ref().map(|k| *k.get_ref()) == Some(LightKind::Directional) {
            return Err(c.err(
                r.span(),
                "light.range applies to point and spot lights, not directional ones",
            ));
        }
        if !(x.is_finite() && x > 0.0 && x <= 1e30) {
            return Err(c.err(
                r.span(),
                format!("light.range = {x}: expected a distance above 0 (up to 1e30)"),
            ));
        }
    }
    let inner = l.inner_angle.as_ref().map(|v| *v.get_ref()).unwrap_or(20.0);
    let outer = l.outer_angle.as_ref().map(|v| *v.get_ref()).unwrap_or(30.0);
    if inner > outer {
        let span = l
            .inner_angle
            .as_ref()
            .or(l.outer_angle.as_ref())
            .map(|s| s.span())
            .unwrap_or(0..0);
        return Err(c.err(
            span,
            format!("light.inner_angle ({inner}) must not exceed light.outer_angle ({outer})"),
        ));
    }
    Ok(())
}

fn validate_camera_keys(c: &Ctx, cam: &CameraDesc) -> Result<(), Error> {
    if cam.keys.is_empty() {
        if let Some(i) = &cam.interpolation {
            return Err(c.err(i.span(), "camera.interpolation needs [[camera.keys]]"));
        }
        return Ok(());
    }
    for (what, span) in [
        ("eye", cam.eye.as_ref().map(|v| v.span())),
        ("target", cam.target.as_ref().map(|v| v.span())),
    ] {
        if let Some(span) = span {
            return Err(c.err(
                span,
                format!(
                    "camera.{what}: a camera with [[camera.keys]] takes its {what} from the keys"
                ),
            ));
        }
    }
    let orthographic = matches!(
        cam.projection.as_ref().map(|p| *p.get_ref()),
        Some(Projection::Orthographic)
    );
    let mut last: Option<i64> = None;
    for k in &cam.keys {
        let k = k.get_ref();
        let f = *k.frame.get_ref();
        if !(0..=1_000_000).contains(&f) {
            return Err(c.err(
                k.frame.span(),
                format!("camera.keys.frame = {f}: expected a frame from 0 to 1000000"),
            ));
        }
        if let Some(prev) = last
            && f <= prev
        {
            return Err(c.err(
                k.frame.span(),
                format!(
                    "camera.keys: frame {f} comes after frame {prev}: keys must be in increasing frame order"
                ),
            ));
        }
        last = Some(f);
        c.vec3(&Some(k.eye.clone()), "camera.keys.eye")?;
        c.vec3(&Some(k.target.clone()), "camera.keys.target")?;
        c.direction(&k.up, "camera.keys.up")?;
        c.float_range(&k.fov, "camera.keys.fov", 0.01, 179.0)?;
        if let (Some(fov), true) = (&k.fov, orthographic) {
            return Err(c.err(fov.span(), "camera.keys.fov: the camera is orthographic"));
        }
        if k.eye.get_ref() == k.target.get_ref() {
            return Err(c.err(
                k.target.span(),
                "camera.keys.target must differ from its eye",
            ));
        }
        let up = glam::Vec3::from(
            k.up.as_ref()
                .map(|u| *u.get_ref())
                .or(cam.up.as_ref().map(|u| *u.get_ref()))
                .unwrap_or([0.0, 1.0, 0.0]),
        );
        let view = glam::Vec3::from(*k.target.get_ref()) - glam::Vec3::from(*k.eye.get_ref());
        if view.normalize().cross(up.normalize()).length() < 1e-6 {
            return Err(c.err(
                k.eye.span(),
                "camera.keys: this key looks along its `up` vector: give another `up`",
            ));
        }
    }
    Ok(())
}

pub(super) fn validate_camera(c: &Ctx, cam: &CameraDesc) -> Result<(), Error> {
    validate_camera_keys(c, cam)?;
    c.vec3(&cam.eye, "camera.eye")?;
    c.vec3(&cam.target, "camera.target")?;
    c.direction(&cam.up, "camera.up")?;
    c.float_range(&cam.fov, "camera.fov", 0.01, 179.0)?;
    c.float_range(&cam.height, "camera.height", 1e-6, 1e9)?;
    c.float_range(&cam.near, "camera.near", 1e-7, 1e9)?;
    c.float_range(&cam.far, "camera.far", 1e-6, 1e12)?;
    c.float_range(&cam.elevation, "camera.elevation", -89.0, 89.0)?;
    c.finite(&cam.azimuth, "camera.azimuth")?;
    if let (Some(n), Some(f)) = (&cam.near, &cam.far)
        && f.get_ref() <= n.get_ref()
    {
        return Err(c.err(
            f.span(),
            format!(
                "camera.far ({}) must be greater than camera.near ({})",
                f.get_ref(),
                n.get_ref()
            ),
        ));
    }
    if let (Some(e), Some(t)) = (&cam.eye, &cam.target)
        && e.get_ref() == t.get_ref()
    {
        return Err(c.err(t.span(), "camera.target must differ from camera.eye"));
    }
    Ok(())
}
