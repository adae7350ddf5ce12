//! `[[camera]]` tables and the cameras of glTF files (`model.cameras =
//! true`) to `Camera`: the scene's cameras first, then the imported ones
//! (named by the file, made unique with a suffix); the default framing
//! camera only when there are neither. Near and far planes not given are
//! fitted to the models' bounding sphere.

use glam::{Mat4, Vec3};

use super::get;
use crate::assets::gltf::{GltfCamera, GltfProjection};
use crate::error::Error;
use crate::scene::camera::{Camera, Projection, fitted_planes};
use crate::scene::desc::{self, Ctx, S, SceneDesc};

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
    imported: &[(GltfCamera, Mat4)],
) -> Result<Vec<Camera>, Error> {
    if d.cameras.is_empty() && imported.is_empty() {
        let Bounds { center, radius } = bounds;
        return Ok(vec![Camera::framing("camera".into(), center, radius, 45.0)]);
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
        if cams.iter().any(|c| c.name == name) {
            return Err(ctx.err(c.span(), format!("two cameras are named `{name}`")));
        }
        cams.push(from_desc(c, name, ctx, bounds)?);
    }
    for (g, world) in imported {
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

/// One `[[camera]]`. Defaults: framed on the bounding sphere from +Z (a
/// missing eye or target keeps the framing's offset), up +Y, fov 45.
fn from_desc(c: &S<desc::CameraDesc>, name: String, ctx: &Ctx, b: Bounds) -> Result<Camera, Error> {
    let cd = c.get_ref();
    let fov = get(&cd.fov, 45.0);
    let up = Vec3::from(get(&cd.up, [0.0, 1.0, 0.0])).normalize();
    let framing = || Camera::framing(name.clone(), b.center, b.radius, fov);
    let (eye, target) = match (&cd.eye, &cd.target) {
        (None, None) => {
            let f = framing();
            (f.eye, f.target)
        }
        (Some(e), None) => (Vec3::from(*e.get_ref()), b.center),
        (None, Some(t)) => {
            let t = Vec3::from(*t.get_ref());
            let f = framing();
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
    })
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
    }
}
