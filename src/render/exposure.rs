//! `render.exposure = "auto"` (`Renderer::exposure`): one exposure for the
//! whole sequence, so a turntable does not flicker and every shard of a
//! farm run gets the same value. Up to 8 frames spread over the animation, of every camera, are
//! rendered at most 96 pixels wide (no AO, no supersampling), and the
//! log-average luminance of the pixels showing the models (all pixels when
//! none do) is mapped to middle grey, 0.18.

use super::{DrawList, Frame, Renderer};
use crate::scene::Scene;
use crate::scene::settings::AoMethod;

/// Stops that bring the scene's log-average luminance to 0.18, within
/// [-16, 16]. Depends on the scene only.
pub(super) fn auto_exposure(scene: &Scene) -> f32 {
    let mut small = scene.clone();
    let s = &mut small.settings;
    // The small frames' linear colour does not depend on the exposure.
    (s.auto_exposure, s.exposure) = (false, 0.0);
    let scale = 96.0 / s.width.max(s.height) as f32;
    if scale < 1.0 {
        s.width = ((s.width as f32 * scale).round() as u32).max(1);
        s.height = ((s.height as f32 * scale).round() as u32).max(1);
    }
    (s.msaa, s.ssaa, s.ao.method) = (1, 1, AoMethod::Off);
    let renderer = Renderer::new(&small);
    let total = small.animation.frames.max(1);
    let count = total.min(8);
    let mut frame = Frame::new(0, 0);
    let (mut models, mut all) = ((0.0f64, 0u64), (0.0f64, 0u64));
    for cam in 0..small.cameras.len() {
        for k in 0..count {
            // The scene's own cameras: no index to check.
            let list = DrawList::new(&small, cam, k * total / count);
            renderer.render_frame(list, &mut frame, None);
            for (c, d) in frame.color.iter().zip(&frame.depth) {
                let lum = 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z;
                let l = (lum.max(0.0) as f64 + 1e-4).ln();
                all = (all.0 + l, all.1 + 1);
                if d.is_finite() {
                    models = (models.0 + l, models.1 + 1);
                }
            }
        }
    }
    let (sum, n) = if models.1 > 0 { models } else { all };
    if n == 0 {
        return 0.0;
    }
    let average = (sum / n as f64).exp();
    ((0.18 / average).log2() as f32).clamp(-16.0, 16.0)
}
