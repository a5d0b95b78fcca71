//! Reading user-supplied text files (configurations, reduced bodies, cache entries) without
//! surprises: only regular files, and no more than a stated size, so a path that names a FIFO,
//! a device such as `/dev/urandom` or a huge file gives a clear error instead of a hang or an
//! unbounded read.

use std::io::Read;
use std::path::Path;

/// Size limit for configuration files (a vehicle configuration is a few kB).
pub const CONFIG_LIMIT: u64 = 16 << 20;

/// Size limit for files with modal data (a reduced body with a thousand modes is tens of MB).
pub const DATA_LIMIT: u64 = 1 << 30;

/// Reads `path` as UTF-8 text if it is a regular file of at most `limit` bytes.
pub fn read_limited(path: &Path, limit: u64) -> Result<String, String> {
    let meta =
        std::fs::metadata(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if !meta.is_file() {
        return Err(format!(
            "{} is not a regular file (a directory, FIFO or device cannot be read as text)",
            path.display()
        ));
    }
    if meta.len() > limit {
        return Err(format!(
            "{} has {} bytes, more than the {limit} bytes allowed for it",
            path.display(),
            meta.len()
        ));
    }
    let file =
        std::fs::File::open(path).map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    // The file may grow between the check and the read: read one byte past the limit at most.
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(limit + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| format!("cannot read {}: {e}", path.display()))?;
    if bytes.len() as u64 > limit {
        return Err(format!(
            "{} grew past the {limit} bytes allowed while being read",
            path.display()
        ));
    }
    String::from_utf8(bytes).map_err(|_| format!("{} is not UTF-8 text", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn regular_files_are_read_and_everything_else_is_refused() {
        let dir = std::env::temp_dir().join(format!("emc-text-file-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("a.json");
        std::fs::write(&file, "{\"x\": 1}").unwrap();
        assert_eq!(read_limited(&file, 100).unwrap(), "{\"x\": 1}");
        let err = read_limited(&file, 3).unwrap_err();
        assert!(err.contains("more than the 3 bytes"), "{err}");
        let err = read_limited(&dir, 100).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
        let err = read_limited(Path::new("/dev/urandom"), 100).unwrap_err();
        assert!(err.contains("not a regular file"), "{err}");
        let err = read_limited(&dir.join("missing.json"), 100).unwrap_err();
        assert!(err.contains("cannot read"), "{err}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
