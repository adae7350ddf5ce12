//! `[[model]]` as the file writes it: placement, scale, animation clip,
//! material overrides.

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess, Visitor};

use super::Spanned;
use super::names::read_vec3;
use crate::scene::material::NormalSpace;

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ModelDesc {
    pub name: Option<Spanned<String>>,
    pub path: Spanned<String>,
    pub translate: Option<Spanned<[f32; 3]>>,
    pub rotate: Option<Spanned<[f32; 3]>>,
    pub scale: Option<Spanned<Scale>>,
    pub normalize: Option<Spanned<bool>>,
    pub lights: Option<Spanned<bool>>,
    pub cameras: Option<Spanned<bool>>,
    pub material: Option<Spanned<MaterialOverride>>,
    #[serde(default)]
    pub materials: std::collections::BTreeMap<String, Spanned<MaterialOverride>>,
    /// Version 2: a glTF animation to play, by name or index.
    pub animation: Option<Spanned<ClipRef>>,
    /// Version 3: a glTF file's KHR_materials_variants variant, by name.
    pub variant: Option<Spanned<String>>,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale(pub [f32; 3]);

/// `model.animation`: a clip's name, or its index in the file.
#[derive(Debug, Clone, PartialEq)]
pub enum ClipRef {
    Name(String),
    Index(u64),
}

impl<'de> Deserialize<'de> for ClipRef {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = ClipRef;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("an animation's name (a string) or index (an integer from 0)")
            }
            fn visit_str<E: de::Error>(self, s: &str) -> Result<ClipRef, E> {
                Ok(ClipRef::Name(s.to_string()))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<ClipRef, E> {
                u64::try_from(v)
                    .map(ClipRef::Index)
                    .map_err(|_| E::invalid_value(de::Unexpected::Signed(v), &self))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<ClipRef, E> {
                Ok(ClipRef::Index(v))
            }
        }
        d.deserialize_any(V)
    }
}

impl<'de> Deserialize<'de> for Scale {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Scale;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number or an array [x, y, z]")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Scale, E> {
                Ok(Scale([v as f32; 3]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Scale, E> {
                Ok(Scale([v as f32; 3]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Scale, E> {
                Ok(Scale([v as f32; 3]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Scale, A::Error> {
                Ok(Scale(read_vec3(seq, &self)?))
            }
        }
        d.deserialize_any(V)
    }
}

/// Overrides of MTL values; keys are the MTL keys in lower case.
#[derive(Debug, Deserialize, Default, Clone)]
#[serde(deny_unknown_fields)]
pub struct MaterialOverride {
    pub ka: Option<Spanned<[f32; 3]>>,
    pub kd: Option<Spanned<[f32; 3]>>,
    pub ks: Option<Spanned<[f32; 3]>>,
    pub ke: Option<Spanned<[f32; 3]>>,
    pub ns: Option<Spanned<f32>>,
    pub ni: Option<Spanned<f32>>,
    pub d: Option<Spanned<f32>>,
    pub illum: Option<Spanned<i64>>,
    pub map_ka: Option<Spanned<String>>,
    pub map_kd: Option<Spanned<String>>,
    pub map_ks: Option<Spanned<String>>,
    pub map_ke: Option<Spanned<String>>,
    pub map_ns: Option<Spanned<String>>,
    pub map_d: Option<Spanned<String>>,
    pub map_bump: Option<Spanned<String>>,
    pub norm: Option<Spanned<String>>,
    pub disp: Option<Spanned<String>>,
    pub bump_scale: Option<Spanned<f32>>,
    pub normal_space: Option<Spanned<NormalSpace>>,
    /// Extension: "opaque" | "mask" | "blend" (default: from d, map_d and
    /// the alpha of map_Kd).
    pub alpha_mode: Option<Spanned<AlphaModeDesc>>,
    /// Extension: opacity below which a "mask" pixel is dropped (0.5).
    pub alpha_cutoff: Option<Spanned<f32>>,
    /// Extension: world units per unit of `disp` height (default 1, or the
    /// MTL's `-mm` gain).
    pub disp_scale: Option<Spanned<f32>>,
    /// Extension (pbr shading): metallic factor in [0, 1].
    pub metallic: Option<Spanned<f32>>,
    /// Extension (pbr shading): perceptual roughness in [0, 1].
    pub roughness: Option<Spanned<f32>>,
}

/// The file's spelling of [`crate::scene::material::AlphaMode`].
#[derive(Debug, Deserialize, Clone, Copy, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum AlphaModeDesc {
    Opaque,
    Mask,
    Blend,
}
