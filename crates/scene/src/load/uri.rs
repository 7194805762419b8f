//! Resolving glTF URIs: `data:` URIs (base64) and relative file paths (percent-encoded).

use std::path::Path;

/// Bytes named by a URI, or a message saying why they are unavailable.
pub(crate) fn fetch(uri: &str, base: Option<&Path>) -> Result<Vec<u8>, String> {
    if let Some(rest) = uri.strip_prefix("data:") {
        let Some((header, payload)) = rest.split_once(',') else {
            return Err("data URI without a ',' before its payload".to_string());
        };
        if !header.ends_with(";base64") {
            return Err(
                "data URI is not base64-encoded (only ';base64' data URIs are supported)"
                    .to_string(),
            );
        }
        return base64_decode(payload);
    }
    if uri.contains("://") {
        return Err(format!(
            "URI {uri:?} uses a scheme other than data: or a relative path"
        ));
    }
    let Some(base) = base else {
        return Err(format!(
            "external file {uri:?} referenced from in-memory data (no base directory)"
        ));
    };
    let rel = percent_decode(uri)?;
    let path = base.join(&rel);
    std::fs::read(&path).map_err(|e| format!("cannot read {}: {e}", path.display()))
}

fn percent_decode(s: &str) -> Result<String, String> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes.get(i) {
            Some(b'%') => {
                let hex = bytes
                    .get(i + 1..i + 3)
                    .ok_or_else(|| format!("bad percent escape in URI {s:?}"))?;
                let hex = std::str::from_utf8(hex)
                    .map_err(|_| format!("bad percent escape in URI {s:?}"))?;
                out.push(
                    u8::from_str_radix(hex, 16)
                        .map_err(|_| format!("bad percent escape in URI {s:?}"))?,
                );
                i += 3;
            }
            Some(&b) => {
                out.push(b);
                i += 1;
            }
            None => break,
        }
    }
    String::from_utf8(out).map_err(|_| format!("URI {s:?} does not decode to UTF-8"))
}

fn base64_value(c: u8) -> Option<u32> {
    match c {
        b'A'..=b'Z' => Some(u32::from(c - b'A')),
        b'a'..=b'z' => Some(u32::from(c - b'a') + 26),
        b'0'..=b'9' => Some(u32::from(c - b'0') + 52),
        b'+' | b'-' => Some(62),
        b'/' | b'_' => Some(63),
        _ => None,
    }
}

/// Decodes standard or URL-safe base64, with or without padding.
pub(crate) fn base64_decode(s: &str) -> Result<Vec<u8>, String> {
    let data = s.trim_end_matches('=').as_bytes();
    let mut out = Vec::with_capacity(data.len() * 3 / 4);
    for chunk in data.chunks(4) {
        let mut acc = 0u32;
        for (k, &c) in chunk.iter().enumerate() {
            let v = base64_value(c)
                .ok_or_else(|| format!("invalid base64 character {:?}", c as char))?;
            acc |= v << (18 - 6 * k);
        }
        let n = match chunk.len() {
            4 => 3,
            3 => 2,
            2 => 1,
            _ => return Err("truncated base64 data".to_string()),
        };
        out.extend_from_slice(&acc.to_be_bytes()[1..1 + n]);
    }
    Ok(out)
}

/// Encodes bytes as standard padded base64 (for writing data URIs).
pub(crate) fn base64_encode(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [
            chunk.first().copied().unwrap_or(0),
            chunk.get(1).copied().unwrap_or(0),
            chunk.get(2).copied().unwrap_or(0),
        ];
        let acc = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(ALPHABET[((acc >> (18 - 6 * k)) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_round_trip_and_errors() {
        for n in 0..20u8 {
            let bytes: Vec<u8> = (0..n)
                .map(|i| i.wrapping_mul(37).wrapping_add(200))
                .collect();
            assert_eq!(base64_decode(&base64_encode(&bytes)), Ok(bytes));
        }
        assert_eq!(base64_encode(b"Man"), "TWFu");
        assert_eq!(base64_decode("TWE="), Ok(b"Ma".to_vec()));
        assert!(base64_decode("TWE*").is_err());
        assert!(base64_decode("T").is_err());
    }

    #[test]
    fn data_uri_and_percent_decoding() {
        assert_eq!(
            fetch("data:application/octet-stream;base64,AAEC", None),
            Ok(vec![0, 1, 2])
        );
        assert!(fetch("data:text/plain,hello", None).is_err());
        assert!(fetch("file.bin", None).is_err());
        assert_eq!(percent_decode("a%20b.bin"), Ok("a b.bin".to_string()));
        assert!(percent_decode("a%2").is_err());
    }
}
