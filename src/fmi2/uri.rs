//! `fmuResourceLocation` URIs → local paths.

use std::path::PathBuf;

/// Parses a `file:` URI as FMI tools pass it: `file:///abs/path`, `file:/abs/path`,
/// `file://localhost/abs/path`, with percent-encoded bytes (the `url` crate, which also knows
/// Windows drive letters). Other schemes, remote hosts, relative paths and malformed escapes are
/// refused.
pub fn resource_path(uri: &str) -> Result<PathBuf, String> {
    let after_scheme = uri
        .strip_prefix("file:")
        .ok_or_else(|| format!("resource location \"{uri}\" is not a file: URI"))?;
    // A URL parser makes `file:relative` absolute; FMI tools never mean that.
    if !after_scheme.starts_with('/') {
        return Err(format!(
            "resource location \"{uri}\" is not an absolute path"
        ));
    }
    // The url crate keeps a malformed escape as literal text; a tool never sends one.
    let escapes_ok = after_scheme
        .split('%')
        .skip(1)
        .all(|rest| rest.len() >= 2 && rest.as_bytes()[..2].iter().all(u8::is_ascii_hexdigit));
    if !escapes_ok {
        return Err(format!("resource location \"{uri}\" has a bad %-escape"));
    }
    let url = url::Url::parse(uri).map_err(|e| format!("resource location \"{uri}\": {e}"))?;
    if url
        .host_str()
        .is_some_and(|h| !h.is_empty() && !h.eq_ignore_ascii_case("localhost"))
    {
        return Err(format!(
            "resource location \"{uri}\" names a remote host \"{}\"",
            url.host_str().unwrap_or_default()
        ));
    }
    url.to_file_path()
        .map_err(|()| format!("resource location \"{uri}\" is not a local path"))
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
