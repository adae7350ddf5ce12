//! `[[camera]]` tables and the cameras of glTF files (`model.cameras =
//! true`) to `Camera`: the scene's cameras first, then the imported ones
//! (named by the file, made unique with a suffix); the default camera only
//! when there are neither.
//!
//! A camera without `eye` and `target` (and the default camera) fits the
//! models tightly (version 2): seen from `elevation` degrees above the
//! horizon (default 20) and `azimuth` degrees about +Y (0: from +Z), the
//! models' vertices, as every frame of a turntable places them, fill 85%
//! of the frame's width or height, centred. A model thin along one axis
//! (under a tenth of its largest extent) is seen along that axis, tilted by
//! the elevation, never edge-on.

use std::sync::Arc;

use glam::{Mat4, Vec3};

use super::get;
use crate::assets::gltf::{GltfCamera, GltfProjection};
use crate::error::Error;
use crate::scene::Model;
use crate::scene::animation::Animation;
use crate::scene::camera::{Camera, CameraKey, CameraPath, Projection, fitted_planes};
use crate::scene::desc::{self, Ctx, SceneDesc, Spanned};

/// The default elevation of fitted cameras, degrees above the horizon.
const ELEVATION: f32 = 20.0;
/// The share of the frame's width or height the fitted models fill.
const FILL: f32 = 0.85;
/// Vertices a fit projects at most, per turntable angle.
const FIT_POINTS: usize = 20_000;
/// Turntable angles a fit covers at most.
const FIT_ANGLES: u32 = 24;

/// What fitted cameras fit: the models' vertices over the animation.
pub(super) struct Subject {
    points: Vec<Vec3>,
    /// The thin axis, if the models are flat along one.
    thin: Option<Vec3>,
    aspect: f32,
}

impl Subject {
    /// A sample of the models' vertices (at most `FIT_POINTS`) as every
    /// frame of the turntable places them relative to the camera (at most
    /// `FIT_ANGLES` frames, evenly spread).
    pub(super) fn new(models: &[Model], animation: &Animation, aspect: f32) -> Subject {
        let total: usize = models.iter().map(|m| m.reach().count()).sum();
        let stride = total.div_ceil(FIT_POINTS).max(1);
        let rest: Vec<Vec3> = models
            .iter()
            .flat_map(|m| {
                m.reach()
                    .map(move |p| m.world_from_object.transform_point3(*p))
            })
            .step_by(stride)
            .collect();
        let (lo, hi) = rest.iter().fold(
            (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
            |(lo, hi), p| (lo.min(*p), hi.max(*p)),
        );
        let ext = (hi - lo).max(Vec3::ZERO);
        let thin = [Vec3::X, Vec3::Y, Vec3::Z]
            .into_iter()
            .zip(ext.to_array())
            .filter(|&(_, e)| e < 0.1 * ext.max_element())
            .map(|(a, _)| a)
            .next();
        let mut points = rest.clone();
        if animation.turntable.is_some() {
            let n = animation.frames.min(FIT_ANGLES);
            for k in 1..n {
                let turn = animation.turn(k * animation.frames / n);
                // The camera orbiting is the models turning the other way.
                let m = if animation.rotates_camera() {
                    turn.inverse()
                } else {
                    turn
                };
                points.extend(rest.iter().map(|p| m.transform_point3(*p)));
            }
        }
        Subject {
            points,
            thin,
            aspect,
        }
    }

    /// A camera fitted to the subject from `elevation` and `azimuth`.
    fn camera(&self, name: String, projection: Projection, elevation: f32, azimuth: f32) -> Camera {
        let (e, a) = (elevation.to_radians(), azimuth.to_radians());
        let toward_eye = match self.thin {
            // Flat along Y (a terrain, a floor with props): from above,
            // tilted by the elevation toward the azimuth.
            Some(t) if t == Vec3::Y => Vec3::new(a.sin() * e.sin(), e.cos(), a.cos() * e.sin()),
            // Flat along X or Z (a panel): along the axis, tilted up.
            Some(t) => (t * e.cos() + Vec3::Y * e.sin()).normalize(),
            None => Vec3::new(a.sin() * e.cos(), e.sin(), a.cos() * e.cos()),
        };
        if self.points.is_empty() {
            return Camera::framing(name, Vec3::ZERO, 1.0, 45.0);
        }
        Camera::fitted(
            name,
            &self.points,
            toward_eye,
            projection,
            self.aspect,
            FILL,
        )
    }
}

/// The models' bounding sphere at rest, which default cameras frame.
#[derive(Debug, Clone, Copy)]
pub(super) struct Bounds {
    pub center: Vec3,
    pub radius: f32,
}

pub(super) fn build(
    d: &SceneDesc,
    ctx: &Ctx,
    bounds: Bounds,
    subject: &Subject,
    imported: &[(GltfCamera, Mat4)],
    animation: &Animation,
) -> Result<Vec<Camera>, Error> {
    // `animation.turntable.elevation`: fitted cameras look from it, cameras
    // with an eye are raised to it (about the pivot); keyed cameras follow
    // their keys.
    let raise = animation.turntable.as_ref().and_then(|t| t.elevation);
    let elevation = raise.unwrap_or(ELEVATION);
    if d.cameras.is_empty() && imported.is_empty() {
        let projection = Projection::Perspective { fov_y: 45.0 };
        return Ok(vec![subject.camera(
            "camera".into(),
            projection,
            elevation,
            0.0,
        )]);
    }
    let mut cams: Vec<Camera> = Vec::new();
    let several = d.cameras.len() > 1;
    for (i, c) in d.cameras.iter().enumerate() {
        let name = c
            .get_ref()
            .name
            .as_ref()
            .map(|n| n.get_ref().clone())
            .unwrap_or_else(|| {
                if several {
                    format!("camera{i}")
                } else {
                    "camera".into()
                }
            });
        if let Err(m) = check_name(&name) {
            let span = c.get_ref().name.as_ref().map_or(c.span(), |n| n.span());
            return Err(ctx.err(span, format!("camera.name = {name:?}: {m}")));
        }
        if cams.iter().any(|c| c.name == name) {
            return Err(ctx.err(c.span(), format!("two cameras are named `{name}`")));
        }
        let mut cam = from_desc(c, name, ctx, bounds, subject, elevation)?;
        let cd = c.get_ref();
        if let Some(e) = raise
            && cd.keys.is_empty()
            && (cd.eye.is_some() || cd.target.is_some())
        {
            cam.eye = animation.raise(cam.eye, e);
        }
        cams.push(cam);
    }
    for (g, world) in imported {
        if let Err(m) = check_name(&g.name) {
            return Err(Error::SceneGlobal {
                file: ctx.file.to_path_buf(),
                message: format!(
                    "a glTF camera imported by model.cameras = true is named {:?}: {m}",
                    g.name
                ),
            });
        }
        let mut name = g.name.clone();
        let mut k = 1;
        while cams.iter().any(|c| c.name == name) {
            k += 1;
            name = format!("{}_{k}", g.name);
        }
        cams.push(from_gltf(g, *world, name, bounds));
    }
    Ok(cams)
}

/// A camera's name goes into output file names (`{camera}`): it may not
/// lead out of the output folder.
fn check_name(name: &str) -> Result<(), String> {
    if name.contains(['/', '\\', '\0']) || name == ".." || name == "." {
        return Err(
            "a camera's name goes into output file names, so it may not contain `/`, `\\` or be `.` or `..`"
                .into(),
        );
    }
    Ok(())
}

/// One `[[camera]]`. Without `eye` and `target`: fitted (with its fov or
/// orthographic projection, `elevation`, `azimuth`, and its `near`/`far`
/// when given). With one of them: the other from the fitted camera's
/// offset (a missing target is the models' center). Up +Y, fov 45.
fn from_desc(
    c: &Spanned<desc::CameraDesc>,
    name: String,
    ctx: &Ctx,
    b: Bounds,
    subject: &Subject,
    default_elevation: f32,
) -> Result<Camera, Error> {
    let cd = c.get_ref();
    let fov = get(&cd.fov, 45.0);
    let up = Vec3::from(get(&cd.up, [0.0, 1.0, 0.0])).normalize();
    let orthographic = matches!(
        cd.projection.as_ref().map(|p| *p.get_ref()),
        Some(desc::Projection::Orthographic)
    );
    let fitted = || {
        let projection = if orthographic {
            Projection::Orthographic { height: 1.0 }
        } else {
            Projection::Perspective { fov_y: fov }
        };
        let (e, a) = (get(&cd.elevation, default_elevation), get(&cd.azimuth, 0.0));
        subject.camera(name.clone(), projection, e, a)
    };
    if !cd.keys.is_empty() {
        return Ok(keyed(cd, name, up, fov, b));
    }
    if cd.eye.is_none() && cd.target.is_none() {
        let mut f = fitted();
        if let Some(h) = &cd.height {
            f.projection = match f.projection {
                Projection::Orthographic { .. } => Projection::Orthographic {
                    height: *h.get_ref(),
                },
                p => p,
            };
        }
        f.near = get(&cd.near, f.near);
        f.far = get(&cd.far, f.far.max(f.near * 2.0));
        if f.far <= f.near {
            return Err(ctx.err(
                c.span(),
                format!(
                    "camera `{name}`: far ({}) must be greater than near ({})",
                    f.far, f.near
                ),
            ));
        }
        return Ok(f);
    }
    let (eye, target) = match (&cd.eye, &cd.target) {
        (None, None) => {
            let f = fitted();
            (f.eye, f.target)
        }
        (Some(e), None) => (Vec3::from(*e.get_ref()), b.center),
        (None, Some(t)) => {
            let t = Vec3::from(*t.get_ref());
            let f = fitted();
            (t + (f.eye - f.target), t)
        }
        (Some(e), Some(t)) => (Vec3::from(*e.get_ref()), Vec3::from(*t.get_ref())),
    };
    if (target - eye).length_squared() == 0.0 {
        return Err(ctx.err(c.span(), "the camera's eye is at its target"));
    }
    if (target - eye).normalize().cross(up).length() < 1e-6 {
        return Err(ctx.err(
            c.span(),
            "the camera looks along its `up` vector: give another `up`",
        ));
    }
    let projection = match cd.projection.as_ref().map(|p| *p.get_ref()) {
        None | Some(desc::Projection::Perspective) => Projection::Perspective { fov_y: fov },
        Some(desc::Projection::Orthographic) => Projection::Orthographic {
            height: get(&cd.height, b.radius * 2.0),
        },
    };
    let (fit_near, fit_far) = fitted_planes((b.center - eye).length(), b.radius);
    let near = get(&cd.near, fit_near);
    let far = get(&cd.far, fit_far.max(near * 2.0));
    if far <= near {
        return Err(ctx.err(
            c.span(),
            format!("camera `{name}`: far ({far}) must be greater than near ({near})"),
        ));
    }
    Ok(Camera {
        name,
        eye,
        target,
        up,
        projection,
        near,
        far,
        path: None,
    })
}

/// A camera on a path of `[[camera.keys]]` (validated: at least one key,
/// frames increasing). It is the first key's camera; each frame places it
/// along the path (`CameraPath::at`), with near and far fitted to the
/// models from where the eye is unless the camera gives them.
fn keyed(cd: &desc::CameraDesc, name: String, up: Vec3, fov: f32, b: Bounds) -> Camera {
    let keys: Vec<CameraKey> = cd
        .keys
        .iter()
        .map(|k| {
            let k = k.get_ref();
            CameraKey {
                frame: *k.frame.get_ref() as u32,
                eye: Vec3::from(*k.eye.get_ref()),
                target: Vec3::from(*k.target.get_ref()),
                up: k
                    .up
                    .as_ref()
                    .map(|u| Vec3::from(*u.get_ref()).normalize())
                    .unwrap_or(up),
                fov: k.fov.as_ref().map(|f| *f.get_ref()),
            }
        })
        .collect();
    let projection = match cd.projection.as_ref().map(|p| *p.get_ref()) {
        None | Some(desc::Projection::Perspective) => Projection::Perspective { fov_y: fov },
        Some(desc::Projection::Orthographic) => Projection::Orthographic {
            height: get(&cd.height, b.radius * 2.0),
        },
    };
    let user_planes = cd.near.is_some() || cd.far.is_some();
    let first = keys[0].clone();
    let (fit_near, fit_far) = fitted_planes((b.center - first.eye).length(), b.radius);
    let near = get(&cd.near, fit_near);
    let far = get(&cd.far, fit_far.max(near * 2.0));
    let path = CameraPath {
        interpolation: cd
            .interpolation
            .as_ref()
            .map(|i| *i.get_ref())
            .unwrap_or_default(),
        fit_planes: (!user_planes).then_some((b.center, b.radius)),
        projection,
        keys,
    };
    let base = Camera {
        name,
        eye: first.eye,
        target: first.target,
        up: first.up,
        projection,
        near,
        far,
        path: None,
    };
    let placed = path.at(&base, first.frame);
    Camera {
        path: Some(Arc::new(path)),
        ..placed
    }
}

/// A glTF camera placed with its model; it looks at a point straight ahead
/// as far as the models' center, and the model's scale applies to its
/// planes and orthographic height.
fn from_gltf(g: &GltfCamera, world: Mat4, name: String, b: Bounds) -> Camera {
    let eye = world.transform_point3(g.eye);
    let forward = world
        .transform_vector3(g.forward)
        .try_normalize()
        .unwrap_or(Vec3::NEG_Z);
    let up = world
        .transform_vector3(g.up)
        .try_normalize()
        .unwrap_or(Vec3::Y);
    let up = if forward.cross(up).length() < 1e-6 {
        forward.any_orthonormal_vector()
    } else {
        up
    };
    let dist = (b.center - eye).dot(forward).max(b.radius * 1e-3).max(1e-6);
    let s = world.transform_vector3(g.forward).length().max(1e-20);
    let (_, fit_far) = fitted_planes((b.center - eye).length(), b.radius);
    let near = (g.near * s).max(1e-6);
    let far = g.far.map(|f| f * s).unwrap_or(fit_far).max(near * 2.0);
    Camera {
        name,
        eye,
        target: eye + forward * dist,
        up,
        projection: match g.projection {
            GltfProjection::Perspective { fov_y } => Projection::Perspective { fov_y },
            GltfProjection::Orthographic { height } => {
                Projection::Orthographic { height: height * s }
            }
        },
        near,
        far,
        path: None,
    }
}
