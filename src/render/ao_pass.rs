//! The AO pass: ambient occlusion of the whole frame from its geometry
//! buffer, by GTAO over the depth buffer or by rays through the scene's
//! BVHs. It runs between visibility and shading, which multiplies the
//! ambient term by it.

use super::draw_list::DrawList;
use crate::raytrace::Tracer;
use crate::scene::settings::AoMethod;
use crate::shade::ao::{self, AoView, GPixel};

/// Per pixel, 1 = unoccluded. `tracer`: the frame's ray tracer (needed
/// for `AoMethod::Raytraced`, unused otherwise).
pub(super) fn occlusion(
    setup: &DrawList,
    gbuf: &[GPixel],
    width: u32,
    height: u32,
    tracer: Option<&Tracer>,
) -> Vec<f32> {
    let s = &setup.scene.settings;
    match (s.ao.method, tracer) {
        (AoMethod::Raytraced, Some(tracer)) => {
            ao::raytraced(tracer, gbuf, width, s.ao.samples, s.ao.radius)
        }
        _ => {
            let view = AoView::new(&setup.camera, width, height);
            let radius = s.ao.radius.unwrap_or(setup.scene.bounds_radius * 0.2);
            ao::gtao(gbuf, &view, radius, s.ao.samples)
        }
    }
}
