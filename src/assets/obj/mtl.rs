//! MTL material libraries, read leniently: what cannot be understood is a
//! warning naming the file and line, and the material keeps its defaults
//! for that key. Names may contain spaces; an empty `newmtl` is named by
//! its position (`material3`); `Kd 0.5` is grey.

use std::path::Path;

use super::parse::{numbers, split_tag};
use super::{MapSpec, MtlMaterial, parse_map};

/// Keys of MTL's PBR extension and of renderers' dialects that softraster
/// reads no value from (sheen, anisotropy, transmission filter, ...); they
/// are skipped without a warning.
const SILENT: &[&str] = &[
    "Tf",
    "sharpness",
    "refl",
    "map_refl",
    "Ps",
    "aniso",
    "anisor",
    "map_Ps",
    "Km",
    "map_aat",
    "decal",
    "map_Ni",
];

/// The materials of one library, each with map paths relative to it.
pub fn parse(path: &Path, text: &str, warnings: &mut Vec<String>) -> Vec<MtlMaterial> {
    let base = path.parent().unwrap_or(Path::new("."));
    let mut mats: Vec<MtlMaterial> = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line_no = i + 1;
        let line = raw.split('#').next().unwrap_or("").trim();
        let Some((tag, rest)) = split_tag(line) else {
            continue;
        };
        let rest = rest.trim();
        let mut warn = |msg: String| {
            warnings.push(format!("{}:{line_no}: {msg}: `{line}`", path.display()));
        };
        if tag == "newmtl" {
            let name = if rest.is_empty() {
                format!("material{}", mats.len())
            } else {
                rest.to_string()
            };
            mats.push(MtlMaterial {
                name,
                unnamed: rest.is_empty(),
                ..Default::default()
            });
            continue;
        }
        let Some(m) = mats.last_mut() else {
            warn("a material key before any `newmtl`; ignored".into());
            continue;
        };
        let color = |warn: &mut dyn FnMut(String)| -> Option<[f32; 3]> {
            if rest.starts_with("spectral") || rest.starts_with("xyz") {
                warn(format!("{tag}: spectral and CIE XYZ colours are not read"));
                return None;
            }
            match numbers(rest).as_deref() {
                Ok([g]) if g.is_finite() => Some([*g; 3]),
                Ok([r, g, b]) if [r, g, b].iter().all(|v| v.is_finite()) => Some([*r, *g, *b]),
                _ => {
                    warn(format!("{tag}: expected one or three numbers"));
                    None
                }
            }
        };
        let scalar = |warn: &mut dyn FnMut(String)| -> Option<f32> {
            match rest
                .split_whitespace()
                .next()
                .and_then(super::parse::number)
            {
                Some(v) if v.is_finite() => Some(v),
                _ => {
                    warn(format!("{tag}: expected a number"));
                    None
                }
            }
        };
        let map = |warn: &mut dyn FnMut(String)| -> Option<MapSpec> {
            parse_map(rest, base)
                .map_err(|msg| warn(format!("{msg}; the map is ignored")))
                .ok()
        };
        match tag {
            "Ka" => m.ka = color(&mut warn).or(m.ka),
            "Kd" => m.kd = color(&mut warn).or(m.kd),
            "Ks" => m.ks = color(&mut warn).or(m.ks),
            "Ke" => m.ke = color(&mut warn).or(m.ke),
            "Ns" => m.ns = scalar(&mut warn).or(m.ns),
            "Ni" => m.ni = scalar(&mut warn).or(m.ni),
            "d" => {
                // `d -halo 0.5`: the halo form keeps the plain value.
                let v = rest.trim_start_matches("-halo").trim();
                m.d = super::parse::number(v.split_whitespace().next().unwrap_or(""))
                    .filter(|v| v.is_finite())
                    .or_else(|| {
                        warn("d: expected a number".into());
                        None
                    })
                    .or(m.d);
            }
            "Tr" => m.d = scalar(&mut warn).map(|t| 1.0 - t).or(m.d),
            "illum" => {
                m.illum = match rest.split_whitespace().next().map(str::parse::<u8>) {
                    Some(Ok(v)) => Some(v),
                    _ => {
                        warn("illum: expected a whole number 0-10".into());
                        m.illum
                    }
                }
            }
            "map_Ka" => m.map_ka = map(&mut warn).or(m.map_ka.take()),
            "map_Kd" => m.map_kd = map(&mut warn).or(m.map_kd.take()),
            "map_Ks" => m.map_ks = map(&mut warn).or(m.map_ks.take()),
            "map_Ke" => m.map_ke = map(&mut warn).or(m.map_ke.take()),
            "map_Ns" => m.map_ns = map(&mut warn).or(m.map_ns.take()),
            "map_d" => m.map_d = map(&mut warn).or(m.map_d.take()),
            "map_Bump" | "map_bump" | "bump" => m.map_bump = map(&mut warn).or(m.map_bump.take()),
            "norm" | "map_Kn" => m.norm = map(&mut warn).or(m.norm.take()),
            "disp" => m.disp = map(&mut warn).or(m.disp.take()),
            "Pr" => m.pr = scalar(&mut warn).or(m.pr),
            "Pm" => m.pm = scalar(&mut warn).or(m.pm),
            "Pc" => m.pc = scalar(&mut warn).or(m.pc),
            "Pcr" => m.pcr = scalar(&mut warn).or(m.pcr),
            "map_Pr" => m.map_pr = map(&mut warn).or(m.map_pr.take()),
            "map_Pm" => m.map_pm = map(&mut warn).or(m.map_pm.take()),
            t if SILENT.contains(&t) => {}
            t => warn(format!("unknown material key `{t}` ignored")),
        }
    }
    mats
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lenient_reading() {
        let mut w = Vec::new();
        let mats = parse(
            Path::new("/m/a.mtl"),
            "Kd 1 1 1\nnewmtl my red paint\nKd 1\nKs 1 0\nNs x\nmap_Kd -bm\nfoo 1\nPr 0.5\n\
             newmtl\nd -halo 0.25\nTr 0.5\nnewmtl last\nKd 0.1 0.2 0.3 # comment\n",
            &mut w,
        );
        assert_eq!(mats.len(), 3);
        assert_eq!(mats[0].name, "my red paint");
        assert_eq!(mats[0].kd, Some([1.0; 3]));
        assert_eq!(mats[0].ks, None);
        assert_eq!(mats[0].ns, None);
        assert_eq!(mats[0].map_kd, None);
        assert_eq!(mats[1].name, "material1");
        assert_eq!(mats[1].d, Some(0.5));
        assert_eq!(mats[2].kd, Some([0.1, 0.2, 0.3]));
        assert_eq!(mats[0].pr, Some(0.5));
        // before newmtl, Ks, Ns, map_Kd, foo
        assert_eq!(w.len(), 5, "{w:#?}");
        assert!(w[0].starts_with("/m/a.mtl:1: "), "{}", w[0]);
        assert!(w[4].contains("unknown material key `foo`"), "{}", w[4]);
    }
}
