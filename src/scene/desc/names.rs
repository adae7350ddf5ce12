//! The file's names of the renderer's values (the spelling lives here,
//! the types with their stages: `scene::settings` and what it
//! re-exports), and the three-number arrays several values take.

use serde::Deserialize;
use serde::de::{self, Deserializer, SeqAccess};

use crate::scene::animation::TurntableTarget;
use crate::scene::camera::Interpolation;
use crate::scene::material::NormalSpace;
use crate::scene::settings::{
    AddressMode, AoMethod, CullMode, DepthMode, GifDither, ShadingMode, ShadowMethod,
    TextureFilter, Tonemap,
};

/// `Deserialize` for a renderer type from the names the file uses for its
/// values; anything else is "unknown variant `x`, expected one of ...".
macro_rules! file_names {
    ($t:ident { $($name:literal => $v:ident),+ $(,)? }) => {
        impl<'de> Deserialize<'de> for $t {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<$t, D::Error> {
                const NAMES: &[&str] = &[$($name),+];
                let s = String::deserialize(d)?;
                match s.as_str() {
                    $($name => Ok($t::$v),)+
                    other => Err(de::Error::unknown_variant(other, NAMES)),
                }
            }
        }
    };
}

file_names!(ShadingMode {
    "auto" => Auto, "blinn-phong" => BlinnPhong, "pbr" => Pbr, "flat" => Flat,
    "gouraud" => Gouraud, "unlit" => Unlit, "normals" => Normals, "depth" => Depth,
    "wireframe" => Wireframe,
});
file_names!(TextureFilter {
    "nearest" => Nearest, "bilinear" => Bilinear, "trilinear" => Trilinear,
    "anisotropic" => Anisotropic,
});
file_names!(AddressMode {
    "repeat" => Repeat, "mirror" => Mirror, "clamp" => Clamp, "border" => Border,
});
file_names!(CullMode { "auto" => Auto, "back" => Back, "front" => Front, "none" => None });
file_names!(DepthMode { "reverse-z" => ReverseZ, "standard" => Standard });
file_names!(ShadowMethod {
    "off" => Off, "hard" => Hard, "pcf" => Pcf, "raytraced" => Raytraced,
});
// The screen-space method is GTAO; the file calls it `ssao`.
file_names!(AoMethod { "off" => Off, "ssao" => Gtao, "raytraced" => Raytraced });
file_names!(Tonemap {
    "clamp" => Clamp, "reinhard" => Reinhard, "aces" => Aces, "aces-hill" => AcesHill,
    "pbr-neutral" => PbrNeutral, "agx" => Agx,
});
file_names!(GifDither {
    "none" => None, "ordered" => Ordered, "floyd-steinberg" => FloydSteinberg,
});
file_names!(NormalSpace { "tangent" => Tangent, "object" => Object });
file_names!(TurntableTarget { "models" => Models, "camera" => Camera });

pub(super) fn read_vec3<'de, A: SeqAccess<'de>>(
    mut seq: A,
    exp: &dyn de::Expected,
) -> Result<[f32; 3], A::Error> {
    let mut out = [0.0f32; 3];
    for (i, slot) in out.iter_mut().enumerate() {
        *slot = seq
            .next_element::<f32>()?
            .ok_or_else(|| de::Error::invalid_length(i, exp))?;
    }
    if seq.next_element::<de::IgnoredAny>()?.is_some() {
        return Err(de::Error::invalid_length(4, exp));
    }
    Ok(out)
}

file_names!(Interpolation {
    "smooth" => Smooth,
    "linear" => Linear,
});
