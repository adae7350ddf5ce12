//! DirectDraw Surface (DDS) textures: the first mip level of a 2D texture,
//! block-compressed (BC1-BC5 and BC7, by the `bcdec_rs` crate) or
//! uncompressed (8 to 32 bits per texel with channel masks, and the DX10
//! header's RGBA8/BGRA8 formats), as row-major RGBA8 texels. Cube maps,
//! arrays, volumes, float and BC6H formats are refused by name; a header
//! whose sizes disagree with the file is refused before any allocation.

/// Largest width or height read (as the other decoders' limits).
const MAX_SIDE: u32 = 16384;

/// Row-major RGBA8 texels of a decoded DDS image.
#[derive(Debug)]
pub struct Decoded {
    pub width: u32,
    pub height: u32,
    pub texels: Vec<[u8; 4]>,
}

/// Whether `bytes` start like a DDS file.
pub fn is_dds(bytes: &[u8]) -> bool {
    bytes.starts_with(b"DDS ")
}

/// How texels are stored (shared with the KTX2 reader).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Format {
    Bc1,
    Bc2,
    Bc3,
    Bc4,
    /// Two channels (a normal map's x and y): z is reconstructed.
    Bc5,
    Bc7,
    /// Uncompressed: bytes per texel and the R, G, B, A masks (A 0: opaque).
    Masked {
        bytes: usize,
        masks: [u32; 4],
    },
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    b.get(at..at + 4)
        .map(|s| u32::from_le_bytes([s[0], s[1], s[2], s[3]]))
}

/// The bytes decoding level 0 takes (its RGBA8 texels), from the header,
/// or None when the header is cut short.
pub fn decode_bytes(b: &[u8]) -> Option<u64> {
    let (height, width) = (u32_at(b, 12)?, u32_at(b, 16)?);
    // Past the largest side `decode` refuses it with its own message.
    (width <= MAX_SIDE && height <= MAX_SIDE).then(|| width as u64 * height as u64 * 4)
}

/// Decodes level 0 of a DDS file, or says why it cannot.
pub fn decode(b: &[u8]) -> Result<Decoded, String> {
    if !is_dds(b) {
        return Err("not a DDS file".into());
    }
    let field = |at: usize| u32_at(b, at).ok_or("the DDS header is cut short");
    if field(4)? != 124 {
        return Err("the DDS header size is not 124".into());
    }
    let height = field(12)?;
    let width = field(16)?;
    let depth_flag = field(8)? & 0x80_0000 != 0;
    let caps2 = field(112)?;
    if caps2 & 0x200 != 0 {
        return Err("DDS cube maps are not supported as textures".into());
    }
    if depth_flag && field(24)? > 1 || caps2 & 0x20_0000 != 0 {
        return Err("DDS volume textures are not supported".into());
    }
    if width == 0 || height == 0 || width > MAX_SIDE || height > MAX_SIDE {
        return Err(format!(
            "DDS size {width}x{height} is outside 1..{MAX_SIDE} texels a side"
        ));
    }
    let pf_flags = field(80)?;
    let four_cc = b.get(84..88).ok_or("the DDS header is cut short")?;
    let (format, data_at) = if pf_flags & 0x4 != 0 {
        match four_cc {
            b"DXT1" => (Format::Bc1, 128),
            b"DXT2" | b"DXT3" => (Format::Bc2, 128),
            b"DXT4" | b"DXT5" => (Format::Bc3, 128),
            b"ATI1" | b"BC4U" => (Format::Bc4, 128),
            b"ATI2" | b"BC5U" => (Format::Bc5, 128),
            b"DX10" => (dx10_format(b)?, 148),
            other => {
                return Err(format!(
                    "DDS pixel format `{}` is not supported (BC1-BC5, BC7 and 8-bit RGBA are)",
                    String::from_utf8_lossy(other)
                ));
            }
        }
    } else if pf_flags & (0x40 | 0x2_0000 | 0x2) != 0 {
        // RGB, luminance or alpha-only, by masks.
        let bits = field(88)?;
        if !matches!(bits, 8 | 16 | 24 | 32) {
            return Err(format!("DDS texels of {bits} bits are not supported"));
        }
        let alpha = if pf_flags & 0x1 != 0 || pf_flags & 0x2 != 0 {
            field(104)?
        } else {
            0
        };
        let mut masks = [field(92)?, field(96)?, field(100)?, alpha];
        if pf_flags & 0x2_0000 != 0 {
            // Luminance: grey from the red mask.
            masks[1] = masks[0];
            masks[2] = masks[0];
        }
        (
            Format::Masked {
                bytes: bits as usize / 8,
                masks,
            },
            128,
        )
    } else {
        return Err("the DDS pixel format names neither a FourCC nor RGB masks".into());
    };
    let data = b.get(data_at..).unwrap_or(&[]);
    let texels = unpack(format, data, width, height).map_err(|e| format!("the DDS file {e}"))?;
    Ok(Decoded {
        width,
        height,
        texels,
    })
}

/// Row-major RGBA8 texels of a `width` x `height` image stored as `format`
/// at the start of `data`; an error (completing "the ... file") when
/// `data` is too short.
pub(super) fn unpack(
    format: Format,
    data: &[u8],
    width: u32,
    height: u32,
) -> Result<Vec<[u8; 4]>, String> {
    let (w, h) = (width as usize, height as usize);
    let (bw, bh) = (w.div_ceil(4), h.div_ceil(4));
    let needed = match format {
        Format::Bc1 | Format::Bc4 => bw * bh * 8,
        Format::Bc2 | Format::Bc3 | Format::Bc5 | Format::Bc7 => bw * bh * 16,
        Format::Masked { bytes, .. } => w * h * bytes,
    };
    if data.len() < needed {
        return Err(format!(
            "holds {} bytes of texels where its {width}x{height} level needs {needed}",
            data.len()
        ));
    }
    let mut texels = vec![[0u8; 4]; w * h];
    match format {
        Format::Masked { bytes, masks } => {
            for (i, t) in texels.iter_mut().enumerate() {
                let s = &data[i * bytes..(i + 1) * bytes];
                let mut v = 0u32;
                for (k, byte) in s.iter().enumerate() {
                    v |= (*byte as u32) << (8 * k);
                }
                for c in 0..4 {
                    t[c] = channel(v, masks[c]).unwrap_or(if c == 3 { 255 } else { 0 });
                }
            }
        }
        _ => {
            let block_bytes = if matches!(format, Format::Bc1 | Format::Bc4) {
                8
            } else {
                16
            };
            let mut out = [0u8; 64];
            for by in 0..bh {
                for bx in 0..bw {
                    let at = (by * bw + bx) * block_bytes;
                    let block = &data[at..at + block_bytes];
                    decode_block(format, block, &mut out);
                    for y in 0..4.min(h - by * 4) {
                        for x in 0..4.min(w - bx * 4) {
                            let o = (y * 4 + x) * 4;
                            texels[(by * 4 + y) * w + bx * 4 + x] =
                                [out[o], out[o + 1], out[o + 2], out[o + 3]];
                        }
                    }
                }
            }
        }
    }
    Ok(texels)
}

/// The DX10 header's format (DXGI_FORMAT values).
fn dx10_format(b: &[u8]) -> Result<Format, String> {
    let dxgi = u32_at(b, 128).ok_or("the DDS DX10 header is cut short")?;
    let dimension = u32_at(b, 132).ok_or("the DDS DX10 header is cut short")?;
    let misc = u32_at(b, 136).ok_or("the DDS DX10 header is cut short")?;
    if misc & 0x4 != 0 {
        return Err("DDS cube maps are not supported as textures".into());
    }
    if dimension == 4 {
        return Err("DDS volume textures are not supported".into());
    }
    let rgba = |r: u32, g: u32, bl: u32, a: u32| Format::Masked {
        bytes: 4,
        masks: [r, g, bl, a],
    };
    Ok(match dxgi {
        71 | 72 => Format::Bc1,
        74 | 75 => Format::Bc2,
        77 | 78 => Format::Bc3,
        80 => Format::Bc4,
        83 => Format::Bc5,
        98 | 99 => Format::Bc7,
        28 | 29 => rgba(0xff, 0xff00, 0xff_0000, 0xff00_0000),
        87 | 91 => rgba(0xff_0000, 0xff00, 0xff, 0xff00_0000),
        88 | 93 => rgba(0xff_0000, 0xff00, 0xff, 0),
        94..=96 => return Err("DDS BC6H (floating-point) textures are not supported".into()),
        other => {
            return Err(format!(
                "DDS DXGI format {other} is not supported (BC1-BC5, BC7 and 8-bit RGBA/BGRA are)"
            ));
        }
    })
}

/// One 4x4 block into RGBA8 rows of 16 bytes.
fn decode_block(format: Format, block: &[u8], out: &mut [u8; 64]) {
    match format {
        Format::Bc1 => bcdec_rs::bc1(block, out, 16),
        Format::Bc2 => bcdec_rs::bc2(block, out, 16),
        Format::Bc3 => bcdec_rs::bc3(block, out, 16),
        Format::Bc7 => bcdec_rs::bc7(block, out, 16),
        Format::Bc4 => {
            let mut r = [0u8; 16];
            bcdec_rs::bc4(block, &mut r, 4, false);
            for (i, v) in r.iter().enumerate() {
                out[i * 4..i * 4 + 4].copy_from_slice(&[*v, *v, *v, 255]);
            }
        }
        Format::Bc5 => {
            let mut rg = [0u8; 32];
            bcdec_rs::bc5(block, &mut rg, 8, false);
            for i in 0..16 {
                let (r, g) = (rg[i * 2], rg[i * 2 + 1]);
                // z of the unit normal whose x and y these encode.
                let x = r as f32 / 127.5 - 1.0;
                let y = g as f32 / 127.5 - 1.0;
                let z = (1.0 - x * x - y * y).max(0.0).sqrt();
                let b = ((z * 0.5 + 0.5) * 255.0).round() as u8;
                out[i * 4..i * 4 + 4].copy_from_slice(&[r, g, b, 255]);
            }
        }
        Format::Masked { .. } => {}
    }
}

/// The value under `mask`, scaled to 0..255 (None for an empty mask).
fn channel(v: u32, mask: u32) -> Option<u8> {
    if mask == 0 {
        return None;
    }
    let shift = mask.trailing_zeros();
    let max = mask >> shift;
    let x = (v & mask) >> shift;
    Some(((x as u64 * 255 + max as u64 / 2) / max as u64) as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A DDS header for `w` x `h` with FourCC `cc` (or RGB masks when None).
    pub(crate) fn header(w: u32, h: u32, cc: Option<&[u8; 4]>) -> Vec<u8> {
        let mut b = vec![0u8; 128];
        b[0..4].copy_from_slice(b"DDS ");
        let put =
            |b: &mut Vec<u8>, at: usize, v: u32| b[at..at + 4].copy_from_slice(&v.to_le_bytes());
        put(&mut b, 4, 124);
        put(&mut b, 8, 0x1007);
        put(&mut b, 12, h);
        put(&mut b, 16, w);
        put(&mut b, 76, 32);
        match cc {
            Some(cc) => {
                put(&mut b, 80, 0x4);
                b[84..88].copy_from_slice(cc);
            }
            None => {
                put(&mut b, 80, 0x41);
                put(&mut b, 88, 32);
                put(&mut b, 92, 0xff_0000);
                put(&mut b, 96, 0xff00);
                put(&mut b, 100, 0xff);
                put(&mut b, 104, 0xff00_0000);
            }
        }
        b
    }

    #[test]
    fn bgra_masks_and_bc1_blocks_decode() {
        // 2x1 BGRA: red, then half-transparent blue.
        let mut b = header(2, 1, None);
        b.extend_from_slice(&[0, 0, 255, 255, 255, 0, 0, 128]);
        let d = decode(&b).unwrap();
        assert_eq!(d.texels, vec![[255, 0, 0, 255], [0, 0, 255, 128]]);
        // BC1, 5x3 (two blocks wide, partial): colour 0 pure green (565),
        // every index 0.
        let mut b = header(5, 3, Some(b"DXT1"));
        for _ in 0..2 {
            b.extend_from_slice(&[0xe0, 0x07, 0x00, 0x00, 0, 0, 0, 0]);
        }
        let d = decode(&b).unwrap();
        assert_eq!((d.width, d.height, d.texels.len()), (5, 3, 15));
        assert!(
            d.texels.iter().all(|t| *t == [0, 255, 0, 255]),
            "{:?}",
            d.texels
        );
    }

    #[test]
    fn header_sizes_do_not_overflow() {
        let mut b = header(u32::MAX, u32::MAX, None);
        assert_eq!(decode_bytes(&b), None);
        b.resize(256, 0);
        assert!(decode(&b).is_err());
    }

    #[test]
    fn malformed_headers_are_refused_not_panicked_on() {
        let good = header(8, 8, Some(b"DXT5"));
        // Too few texel bytes for the size.
        assert!(decode(&good).unwrap_err().contains("needs 64"));
        // Every prefix of a valid file, and junk after the magic.
        let mut full = good.clone();
        full.extend(std::iter::repeat_n(0x5a, 64));
        assert!(decode(&full).is_ok());
        for n in 0..full.len() {
            let _ = decode(&full[..n]);
        }
        let mut huge = header(1 << 20, 4, Some(b"DXT1"));
        huge.extend([0; 64]);
        assert!(decode(&huge).unwrap_err().contains("outside"));
        assert!(
            decode(&header(4, 4, Some(b"ABCD")))
                .unwrap_err()
                .contains("`ABCD`")
        );
        // Random BC7 blocks (any mode, reserved ones included) decode.
        let mut b = header(16, 16, Some(b"DX10"));
        b.extend_from_slice(&[98, 0, 0, 0, 3, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0]);
        let mut x = 0x1234_5678u32;
        for _ in 0..16 * 16 {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            b.push(x as u8);
        }
        assert_eq!(decode(&b).unwrap().texels.len(), 256);
    }
}
