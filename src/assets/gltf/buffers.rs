//! A glTF file's buffers: the GLB binary chunk, data URIs and files
//! beside it (read through `Input`, at most their `byteLength`), and
//! meshopt fallbacks reserved for their decoded views.

use super::*;

pub(super) fn load_buffers(
    doc: &gltf::Document,
    blob: Option<&[u8]>,
    path: &Path,
    input: &Input,
) -> Result<Vec<Vec<u8>>, Error> {
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut out = Vec::new();
    // Room for meshopt-decoded views, bounded by what the real buffers
    // could decode to.
    let real: usize = doc
        .buffers()
        .filter(|b| !crate::assets::meshopt::is_fallback(b))
        .map(|b| b.length())
        .sum();
    for b in doc.buffers() {
        let i = b.index();
        let no_data = matches!(b.source(), gltf::buffer::Source::Bin) && blob.is_none();
        if crate::assets::meshopt::is_fallback(&b) && no_data {
            if b.length() > real.saturating_mul(256) + (1 << 20) {
                return Err(Error::asset(
                    path,
                    None,
                    format!(
                        "buffer {i}: a meshopt fallback of {} bytes is out of proportion",
                        b.length()
                    ),
                ));
            }
            input
                .check(
                    &format!("buffer {i} (a meshopt fallback)"),
                    b.length() as u64,
                )
                .map_err(|m| Error::asset(path, None, m))?;
            out.push(vec![0; b.length()]);
            continue;
        }
        let data = match b.source() {
            gltf::buffer::Source::Bin => blob.map(<[u8]>::to_vec).ok_or_else(|| {
                Error::asset(
                    path,
                    None,
                    format!(
                        "buffer {i} refers to the GLB binary chunk, which the file does not have"
                    ),
                )
            })?,
            gltf::buffer::Source::Uri(uri) => match data_uri(uri) {
                Some(d) => d.map_err(|m| Error::asset(path, None, format!("buffer {i}: {m}")))?,
                None => {
                    // At most its byteLength (a longer file is read that
                    // far; a FIFO or device is refused).
                    let file = dir.join(percent_decode(uri));
                    input
                        .read(&file, Some(path), Some(b.length() as u64))
                        .map_err(|e| match e {
                            Error::Asset {
                                path,
                                line,
                                message,
                            } => Error::Asset {
                                path,
                                line,
                                message: format!("buffer {i}: {message}"),
                            },
                            other => other,
                        })?
                }
            },
        };
        if data.len() < b.length() {
            return Err(Error::asset(
                path,
                None,
                format!(
                    "buffer {i} holds {} bytes but declares {} (truncated file?)",
                    data.len(),
                    b.length()
                ),
            ));
        }
        out.push(data);
    }
    Ok(out)
}

/// `data:[mime];base64,...`: Some(decoded) for a data URI, None otherwise.
pub(super) fn data_uri(uri: &str) -> Option<Result<Vec<u8>, String>> {
    let rest = uri.strip_prefix("data:")?;
    let Some((_, payload)) = rest.split_once(";base64,") else {
        return Some(Err("data URIs must be base64-encoded".into()));
    };
    Some(
        base64::engine::general_purpose::STANDARD
            .decode(payload)
            .map_err(|e| format!("bad base64 data URI: {e}")),
    )
}

pub(super) fn percent_decode(uri: &str) -> String {
    let b = uri.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        if b[i] == b'%'
            && i + 2 < b.len()
            && let (Some(h), Some(l)) = (hex(b[i + 1]), hex(b[i + 2]))
        {
            let v = (h * 16 + l) as u8;
            out.push(v);
            i += 3;
            continue;
        }
        out.push(b[i]);
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn data_uris_and_percent_escapes() {
        assert_eq!(
            data_uri("data:application/octet-stream;base64,AAEC")
                .unwrap()
                .unwrap(),
            vec![0, 1, 2]
        );
        assert!(data_uri("data:text/plain,abc").unwrap().is_err());
        assert!(data_uri("model.bin").is_none());
        assert_eq!(percent_decode("a%20b.bin"), "a b.bin");
        assert_eq!(percent_decode("100%"), "100%");
    }
}
