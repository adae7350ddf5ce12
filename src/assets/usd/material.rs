//! `UsdPreviewSurface` materials as metallic-roughness, and the textures
//! they name: files beside the USD file, or entries of its `.usdz`
//! package.
//!
//! The mapping: `diffuseColor` is the base colour, `metallic` and
//! `roughness` the factors, `emissiveColor` the emission, `normal` the
//! normal map (its usual scale 2 and bias -1 are glTF's), `occlusion`
//! the occlusion map, `opacity` below 1 blends and `opacityThreshold`
//! above 0 cuts out, `ior` and `clearcoat` / `clearcoatRoughness` the
//! glTF extensions' values. Texture channels follow glTF's packing:
//! roughness from green and metallic from blue of one texture become its
//! metallic-roughness map, occlusion from red its occlusion map; other
//! packings keep the constant value, with a warning.

use std::io::{Cursor, Read};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec3, Vec4};
use openusd::gf;
use openusd::schemas::shade::{Channel, read_preview_surface};
use openusd::sdf;
use openusd::usd::Stage;

use crate::assets::gltf::{GltfAlphaMode, GltfClearcoat, GltfMaterial, ImageSource, TexInfo};
use crate::assets::texture::{AddressMode, Wrap};

/// The entries of a `.usdz` package (empty for other files).
pub(super) struct Package {
    path: PathBuf,
    bytes: Option<Arc<[u8]>>,
}

impl Package {
    /// The package of file `path` whose bytes are `bytes`, if it is one.
    pub fn of(path: &Path, bytes: &[u8]) -> Package {
        let usdz = path
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("usdz"));
        Package {
            path: path.to_path_buf(),
            bytes: usdz.then(|| Arc::from(bytes)),
        }
    }

    /// Entry `name` of the package (at most `cap` bytes).
    fn entry(&self, name: &str, cap: u64) -> Option<Arc<[u8]>> {
        let bytes = self.bytes.as_ref()?;
        let mut zip = zip::ZipArchive::new(Cursor::new(&bytes[..])).ok()?;
        let file = zip.by_name(name).ok()?;
        if file.size() > cap {
            return None;
        }
        let mut out = Vec::with_capacity(file.size() as usize);
        file.take(cap).read_to_end(&mut out).ok()?;
        Some(Arc::from(out))
    }
}

/// Where texture `asset` (as the material names it) is: in the package,
/// else beside the file.
fn texture(asset: &str, dir: &Path, package: &Package) -> TexInfo {
    let asset = asset.trim_matches('@');
    // "pkg.usdz[textures/a.png]" names an entry of a package.
    let inner = match (asset.find('['), asset.ends_with(']')) {
        (Some(k), true) => &asset[k + 1..asset.len() - 1],
        _ => asset,
    };
    let name = inner.trim_start_matches("./");
    let image = match package.entry(name, crate::assets::input::READ_CAP) {
        Some(bytes) => ImageSource::Memory {
            name: PathBuf::from(format!("{}#{name}", package.path.display())),
            bytes,
        },
        None => ImageSource::File(dir.join(name)),
    };
    TexInfo {
        image,
        texcoord: 0,
        transform: glam::Affine2::IDENTITY,
        wrap: Wrap(AddressMode::Repeat, AddressMode::Repeat),
        min_limit: None,
        mag_nearest: false,
    }
}

/// The `UsdPreviewSurface` of material prim `path`, or None where its
/// surface is another shader.
pub(super) fn preview_surface(
    stage: &Stage,
    path: &sdf::Path,
    dir: &Path,
    package: &Package,
    warnings: &mut Vec<String>,
) -> anyhow::Result<Option<GltfMaterial>> {
    let Some(s) = read_preview_surface(stage, path)? else {
        return Ok(None);
    };
    let shader = sdf::Path::new(&s.shader)?;
    let tex = |asset: &str| texture(asset, dir, package);
    let mut g = GltfMaterial::default_material();
    g.name = path.name().unwrap_or("material").to_string();
    let color = |c: &gf::Vec3f| Vec3::new(c.x, c.y, c.z);
    let scalar = |c: &Channel<f32>, default: f32| c.value().copied().unwrap_or(default);
    let base = match &s.diffuse_color {
        Channel::Value(c) => color(c),
        Channel::Texture(t) => {
            g.base_color_tex = Some(tex(t));
            Vec3::ONE
        }
        Channel::Unset => Vec3::splat(0.18),
    };
    let opacity = scalar(&s.opacity, 1.0).clamp(0.0, 1.0);
    g.base_color = base.extend(opacity);
    g.metallic = scalar(&s.metallic, 0.0).clamp(0.0, 1.0);
    g.roughness = scalar(&s.roughness, 0.5).clamp(0.0, 1.0);
    let channel = |input: &str| output_channel(stage, &shader, input);
    match (s.roughness.texture(), s.metallic.texture()) {
        (Some(r), Some(m)) if r == m && channel("roughness") == "g" && channel("metallic") == "b" => {
            g.metallic_roughness_tex = Some(tex(r));
            (g.roughness, g.metallic) = (1.0, 1.0);
        }
        (Some(r), None) if channel("roughness") == "g" => {
            g.metallic_roughness_tex = Some(tex(r));
            g.roughness = 1.0;
        }
        (None, Some(m)) if channel("metallic") == "b" => {
            g.metallic_roughness_tex = Some(tex(m));
            g.metallic = 1.0;
        }
        (None, None) => {}
        _ => warnings.push(format!(
            "material {}: its roughness and metallic textures are not packed as glTF's (green, blue of one texture); their constant values are used",
            path.as_str()
        )),
    }
    if let Some(t) = s.occlusion.texture() {
        if channel("occlusion") == "r" {
            g.occlusion_tex = Some(tex(t));
        } else {
            warnings.push(format!(
                "material {}: its occlusion texture is read from a channel other than red; it is not used",
                path.as_str()
            ));
        }
    }
    if let Some(t) = s.normal.texture() {
        g.normal_tex = Some(tex(t));
    }
    match &s.emissive_color {
        Channel::Value(c) => g.emissive = color(c),
        Channel::Texture(t) => {
            g.emissive = Vec3::ONE;
            g.emissive_tex = Some(tex(t));
        }
        Channel::Unset => {}
    }
    if let Some(t) = s.opacity.texture() {
        // Opacity from the base colour texture's alpha is glTF's alpha.
        let same = s.diffuse_color.texture() == Some(t) && channel("opacity") == "a";
        if same {
            g.alpha_mode = GltfAlphaMode::Blend;
        } else {
            warnings.push(format!(
                "material {}: its opacity texture is not the diffuse texture's alpha; the material is drawn opaque",
                path.as_str()
            ));
        }
    }
    if opacity < 1.0 {
        g.alpha_mode = GltfAlphaMode::Blend;
    }
    let threshold = scalar(&s.opacity_threshold, 0.0);
    if threshold > 0.0 && g.alpha_mode == GltfAlphaMode::Blend {
        g.alpha_mode = GltfAlphaMode::Mask;
        g.alpha_cutoff = threshold;
    }
    if let Some(&ior) = s.ior.value()
        && ior.is_finite()
        && ior >= 1.0
    {
        g.ior = ior;
    }
    let coat = scalar(&s.clearcoat, 0.0);
    if coat > 0.0 {
        g.clearcoat = Some(GltfClearcoat {
            factor: coat.min(1.0),
            texture: None,
            roughness: scalar(&s.clearcoat_roughness, 0.01).clamp(0.0, 1.0),
            roughness_texture: None,
            normal_texture: None,
            normal_scale: 1.0,
        });
    }
    if !g.base_color.is_finite() || !g.emissive.is_finite() {
        g.base_color = Vec4::ONE;
        g.emissive = Vec3::ZERO;
    }
    Ok(Some(g))
}

/// The output (`r`, `g`, `b`, `a`, `rgb`) of the texture that shader
/// input `inputs:<input>` of `shader` connects to ("" without one).
fn output_channel(stage: &Stage, shader: &sdf::Path, input: &str) -> String {
    let attr = format!("{}.inputs:{input}", shader.as_str());
    let Ok(path) = sdf::Path::new(&attr) else {
        return String::new();
    };
    let source = stage.attribute(path).connections().ok();
    source
        .and_then(|c| c.into_iter().next())
        .and_then(|p| {
            p.name()
                .map(|n| n.trim_start_matches("outputs:").to_string())
        })
        .unwrap_or_default()
}
