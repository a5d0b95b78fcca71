//! `fmuResourceLocation` URIs → local paths.

use std::path::PathBuf;

/// Parses a `file:` URI as FMI tools pass it: `file:///abs/path`, `file:/abs/path`,
/// `file://localhost/abs/path`, with percent-encoded bytes. Other schemes and hosts are refused.
pub fn resource_path(uri: &str) -> Result<PathBuf, String> {
    let rest = uri
        .strip_prefix("file:")
        .ok_or_else(|| format!("resource location \"{uri}\" is not a file: URI"))?;
    let path = if let Some(after) = rest.strip_prefix("//") {
        let slash = after.find('/').unwrap_or(after.len());
        let host = &after[..slash];
        if !(host.is_empty() || host.eq_ignore_ascii_case("localhost")) {
            return Err(format!(
                "resource location \"{uri}\" names a remote host \"{host}\""
            ));
        }
        &after[slash..]
    } else {
        rest
    };
    if !path.starts_with('/') {
        return Err(format!(
            "resource location \"{uri}\" is not an absolute path"
        ));
    }
    let bytes = percent_decode(path)
        .ok_or_else(|| format!("resource location \"{uri}\" has a bad %-escape"))?;
    let text = String::from_utf8(bytes)
        .map_err(|_| format!("resource location \"{uri}\" is not UTF-8"))?;
    Ok(PathBuf::from(text))
}

fn percent_decode(s: &str) -> Option<Vec<u8>> {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i] == b'%' {
            let hex = bytes.get(i + 1..i + 3)?;
            let text = std::str::from_utf8(hex).ok()?;
            out.push(u8::from_str_radix(text, 16).ok()?);
            i += 3;
        } else {
            out.push(bytes[i]);
            i += 1;
        }
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_the_forms_tools_use() {
        let want = PathBuf::from("/tmp/my fmu/resources");
        assert_eq!(
            resource_path("file:///tmp/my%20fmu/resources").unwrap(),
            want
        );
        assert_eq!(resource_path("file:/tmp/my%20fmu/resources").unwrap(), want);
        assert_eq!(
            resource_path("file://localhost/tmp/my%20fmu/resources").unwrap(),
            want
        );
        assert_eq!(
            resource_path("file:///tmp/%C3%A4/r").unwrap(),
            PathBuf::from("/tmp/ä/r")
        );
    }

    #[test]
    fn refuses_what_it_cannot_open() {
        assert!(resource_path("http://x/y").is_err());
        assert!(resource_path("file://server/share").is_err());
        assert!(resource_path("file:relative/path").is_err());
        assert!(resource_path("file:///bad%2").is_err());
        assert!(resource_path("file:///bad%zz").is_err());
    }
}
