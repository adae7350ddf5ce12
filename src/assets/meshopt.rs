//! EXT_meshopt_compression: buffer views stored compressed in another
//! buffer, decoded (by the `meshopt` crate's decoders, safe for untrusted
//! input) into the place their fallback buffer reserves for them, so the
//! accessors read them like any view. Every precondition the C decoders
//! assert (strides, counts, filters) is checked here first, and a decoded
//! size is bounded, so a file cannot abort the process or make it allocate
//! without limit.

use serde_json::Value;

/// A decoded view may be at most this many times its compressed size
/// (plus 1 MiB): meshopt compresses 2-10x in practice.
const MAX_RATIO: usize = 256;

/// Decodes every compressed view of `doc` into `buffers`. Fallback
/// buffers (no data of their own) must already be zero-filled to their
/// declared length.
pub fn decode_views(doc: &gltf::Document, buffers: &mut [Vec<u8>]) -> Result<(), String> {
    for view in doc.views() {
        let Some(ext) = view
            .extensions()
            .and_then(|e| e.get("EXT_meshopt_compression"))
        else {
            continue;
        };
        let i = view.index();
        let err = |m: String| format!("buffer view {i} (EXT_meshopt_compression): {m}");
        let c = Compressed::parse(ext).map_err(err)?;
        let src = buffers
            .get(c.buffer)
            .and_then(|b| b.get(c.offset..c.offset.checked_add(c.length)?))
            .ok_or_else(|| {
                err(format!(
                    "bytes {}..{} lie outside buffer {}",
                    c.offset,
                    c.offset.saturating_add(c.length),
                    c.buffer
                ))
            })?
            .to_vec();
        let size = c
            .count
            .checked_mul(c.stride)
            .filter(|s| *s <= c.length.saturating_mul(MAX_RATIO) + (1 << 20))
            .ok_or_else(|| {
                err(format!(
                    "{} elements of {} bytes is too much to decode from {} bytes",
                    c.count, c.stride, c.length
                ))
            })?;
        if size > view.length() {
            return Err(err(format!(
                "decodes to {size} bytes, more than the view's {}",
                view.length()
            )));
        }
        let decoded = c.decode(&src).map_err(err)?;
        let target = buffers
            .get_mut(view.buffer().index())
            .and_then(|b| b.get_mut(view.offset()..view.offset().checked_add(size)?))
            .ok_or_else(|| err("the view lies outside its fallback buffer".into()))?;
        target.copy_from_slice(&decoded);
    }
    Ok(())
}

/// Whether buffer `b` is a meshopt fallback (it has no data; its length
/// is the room the decoded views take).
pub fn is_fallback(b: &gltf::Buffer) -> bool {
    b.extensions()
        .and_then(|e| e.get("EXT_meshopt_compression"))
        .and_then(|e| e.get("fallback"))
        .and_then(Value::as_bool)
        .unwrap_or(false)
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Mode {
    Attributes,
    Triangles,
    Indices,
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Filter {
    None,
    Octahedral,
    Quaternion,
    Exponential,
}

struct Compressed {
    buffer: usize,
    offset: usize,
    length: usize,
    stride: usize,
    count: usize,
    mode: Mode,
    filter: Filter,
}

impl Compressed {
    fn parse(v: &Value) -> Result<Compressed, String> {
        let int = |k: &str, default: Option<u64>| {
            v.get(k)
                .map(|x| x.as_u64().ok_or(format!("`{k}` is not a whole number")))
                .unwrap_or(default.ok_or(format!("`{k}` is missing")))
                .and_then(|x| usize::try_from(x).map_err(|_| format!("`{k}` is too large")))
        };
        let mode = match v.get("mode").and_then(Value::as_str) {
            Some("ATTRIBUTES") => Mode::Attributes,
            Some("TRIANGLES") => Mode::Triangles,
            Some("INDICES") => Mode::Indices,
            other => return Err(format!("unknown mode {other:?}")),
        };
        let filter = match v.get("filter").and_then(Value::as_str).unwrap_or("NONE") {
            "NONE" => Filter::None,
            "OCTAHEDRAL" => Filter::Octahedral,
            "QUATERNION" => Filter::Quaternion,
            "EXPONENTIAL" => Filter::Exponential,
            other => return Err(format!("unknown filter `{other}`")),
        };
        let c = Compressed {
            buffer: int("buffer", None)?,
            offset: int("byteOffset", Some(0))?,
            length: int("byteLength", None)?,
            stride: int("byteStride", None)?,
            count: int("count", None)?,
            mode,
            filter,
        };
        // What the decoders assert.
        let ok = match (c.mode, c.filter) {
            (Mode::Attributes, Filter::None) => {
                c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride)
            }
            (Mode::Attributes, Filter::Octahedral) => c.stride == 4 || c.stride == 8,
            (Mode::Attributes, Filter::Quaternion) => c.stride == 8,
            (Mode::Attributes, Filter::Exponential) => {
                c.stride.is_multiple_of(4) && (4..=256).contains(&c.stride)
            }
            (Mode::Triangles, Filter::None) => {
                (c.stride == 2 || c.stride == 4) && c.count.is_multiple_of(3)
            }
            (Mode::Indices, Filter::None) => c.stride == 2 || c.stride == 4,
            _ => false,
        };
        if !ok {
            return Err(format!(
                "mode {:?} with filter {:?} and byteStride {} (count {}) is not a valid combination",
                c.mode, c.filter, c.stride, c.count
            ));
        }
        Ok(c)
    }

    fn decode(&self, src: &[u8]) -> Result<Vec<u8>, String> {
        let mut out = vec![0u8; self.count * self.stride];
        if self.count == 0 {
            return Ok(out);
        }
        let dst = out.as_mut_ptr().cast::<std::ffi::c_void>();
        // SAFETY: `out` holds exactly count * stride bytes, and `parse`
        // checked the stride, count and filter against what each decoder
        // asserts; the decoders bound their reads by `src.len()`.
        let code = unsafe {
            match self.mode {
                Mode::Attributes => meshopt::ffi::meshopt_decodeVertexBuffer(
                    dst,
                    self.count,
                    self.stride,
                    src.as_ptr(),
                    src.len(),
                ),
                Mode::Triangles => meshopt::ffi::meshopt_decodeIndexBuffer(
                    dst,
                    self.count,
                    self.stride,
                    src.as_ptr(),
                    src.len(),
                ),
                Mode::Indices => meshopt::ffi::meshopt_decodeIndexSequence(
                    dst,
                    self.count,
                    self.stride,
                    src.as_ptr(),
                    src.len(),
                ),
            }
        };
        if code != 0 {
            return Err(format!(
                "the compressed data is malformed (decoder error {code})"
            ));
        }
        // SAFETY: as above; the filters rewrite count elements of `stride`
        // bytes in place, with strides `parse` checked.
        unsafe {
            match self.filter {
                Filter::None => {}
                Filter::Octahedral => {
                    meshopt::ffi::meshopt_decodeFilterOct(dst, self.count, self.stride)
                }
                Filter::Quaternion => {
                    meshopt::ffi::meshopt_decodeFilterQuat(dst, self.count, self.stride)
                }
                Filter::Exponential => {
                    meshopt::ffi::meshopt_decodeFilterExp(dst, self.count, self.stride)
                }
            }
        }
        Ok(out)
    }
}
