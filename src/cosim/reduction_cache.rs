//! On-disk cache of the reduced chassis (DESIGN §4.3).
//!
//! The FMU's resources may be read-only and several processes may instantiate at once, so the
//! reduced model lives in the user's cache directory (`$XDG_CACHE_HOME/engine_mount_chassis`, else
//! `~/.cache/engine_mount_chassis`), or a directory the user names, or nowhere. An entry is keyed
//! by a hash of every input of the reduction and a format version; it stores the full key text, so
//! a hash collision, a foreign or a corrupt file is detected, ignored and rebuilt. Entries are
//! written to a temporary file and renamed into place, so a reader never sees half an entry.
//!
//! Numbers are stored as their IEEE bit patterns: a run that reads the cache gets exactly the
//! numbers of the run that wrote it (a restored FMU state continues bit for bit either way).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::cms::{RecoveryPoint, ReducedChassis};
use crate::model::hybrid_chassis::ChassisReduction;

/// Bumped whenever the entry layout or the reduction method changes.
const FORMAT_VERSION: u32 = 1;
/// Name of the reduction method, part of the key.
const METHOD: &str = "free-interface-modal-truncation";

/// Where the reduced chassis is cached.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CachePolicy {
    /// Always reduce, never read or write a cache.
    Disabled,
    /// The user's cache directory.
    UserCache,
    /// A directory of the user's choice.
    Directory(PathBuf),
}

/// How the reduced chassis was obtained (for the log).
#[derive(Debug, Clone, PartialEq)]
pub enum CacheOutcome {
    /// Read from this entry.
    Hit(PathBuf),
    /// Reduced, and stored at the path (or not stored, with the reason).
    Reduced { stored: Result<PathBuf, String> },
    /// Reduced; caching is disabled or no cache directory is known.
    Uncached,
}

#[derive(Serialize, Deserialize)]
struct EntryPoint {
    name: String,
    node: usize,
    position: [u64; 3],
    shape: Vec<[u64; 6]>,
}

#[derive(Serialize, Deserialize)]
struct Entry {
    format: u32,
    key: String,
    omega: Vec<u64>,
    zeta: Vec<u64>,
    points: Vec<EntryPoint>,
}

fn to_entry(key: &str, r: &ReducedChassis) -> Entry {
    Entry {
        format: FORMAT_VERSION,
        key: key.to_owned(),
        omega: r.omega.iter().map(|v| v.to_bits()).collect(),
        zeta: r.zeta.iter().map(|v| v.to_bits()).collect(),
        points: r
            .points
            .iter()
            .map(|p| EntryPoint {
                name: p.name.clone(),
                node: p.node,
                position: p.position.map(f64::to_bits),
                shape: p.shape.iter().map(|s| s.map(f64::to_bits)).collect(),
            })
            .collect(),
    }
}

fn from_entry(e: Entry) -> ReducedChassis {
    ReducedChassis {
        omega: e.omega.into_iter().map(f64::from_bits).collect(),
        zeta: e.zeta.into_iter().map(f64::from_bits).collect(),
        points: e
            .points
            .into_iter()
            .map(|p| RecoveryPoint {
                name: p.name,
                node: p.node,
                position: p.position.map(f64::from_bits),
                shape: p.shape.into_iter().map(|s| s.map(f64::from_bits)).collect(),
            })
            .collect(),
    }
}

/// FNV-1a, 64 bit: stable across builds and platforms (unlike `std`'s hasher).
fn fnv1a(text: &str) -> u64 {
    text.bytes().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3)
    })
}

/// The user's cache directory for this crate, if the environment names one.
pub fn user_cache_dir() -> Option<PathBuf> {
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| {
            std::env::var_os("HOME")
                .map(PathBuf::from)
                .filter(|p| p.is_absolute())
                .map(|h| h.join(".cache"))
        })?;
    Some(base.join("engine_mount_chassis"))
}

fn key_text(reduction: &ChassisReduction) -> Result<String, String> {
    let inputs = serde_json::to_string(reduction)
        .map_err(|e| format!("cannot describe the chassis reduction: {e}"))?;
    Ok(format!("{METHOD} v{FORMAT_VERSION} {inputs}"))
}

fn read_entry(path: &Path, key: &str) -> Option<ReducedChassis> {
    let text = std::fs::read_to_string(path).ok()?;
    let entry: Entry = serde_json::from_str(&text).ok()?;
    (entry.format == FORMAT_VERSION && entry.key == key).then(|| from_entry(entry))
}

fn write_entry(dir: &Path, path: &Path, entry: &Entry) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot create {}: {e}", dir.display()))?;
    let text = serde_json::to_string(entry).map_err(|e| format!("cannot encode entry: {e}"))?;
    let nanos = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.subsec_nanos())
        .unwrap_or(0);
    let tmp = dir.join(format!(
        ".{}.tmp-{}-{nanos}",
        path.file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default(),
        std::process::id()
    ));
    std::fs::write(&tmp, text).map_err(|e| format!("cannot write {}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        format!("cannot move {} into place: {e}", path.display())
    })
}

/// The reduced chassis for `reduction`: from the cache when a valid entry exists, else reduced
/// (and stored, if the policy allows). The numbers are the same either way.
pub fn load_or_reduce(
    reduction: &ChassisReduction,
    policy: &CachePolicy,
) -> Result<(ReducedChassis, CacheOutcome), String> {
    reduction.validate()?;
    let dir = match policy {
        CachePolicy::Disabled => None,
        CachePolicy::UserCache => user_cache_dir(),
        CachePolicy::Directory(d) => Some(d.clone()),
    };
    let Some(dir) = dir else {
        return Ok((reduction.reduce()?, CacheOutcome::Uncached));
    };
    let key = key_text(reduction)?;
    let path = dir.join(format!("chassis-{:016x}.json", fnv1a(&key)));
    if let Some(hit) = read_entry(&path, &key) {
        return Ok((hit, CacheOutcome::Hit(path)));
    }
    let reduced = reduction.reduce()?;
    let stored = write_entry(&dir, &path, &to_entry(&key, &reduced)).map(|()| path);
    Ok((reduced, CacheOutcome::Reduced { stored }))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> ReducedChassis {
        ReducedChassis {
            omega: vec![0.1 + 0.2, std::f64::consts::PI * 100.0],
            zeta: vec![0.01, 0.1],
            points: vec![RecoveryPoint {
                name: "p".into(),
                node: 3,
                position: [0.5, -0.4, 0.55],
                shape: vec![[1e-3 / 3.0; 6], [-7e-5; 6]],
            }],
        }
    }

    #[test]
    fn entries_round_trip_exactly_and_reject_foreign_keys() {
        let dir = std::env::temp_dir().join(format!("emc-cache-test-{}", std::process::id()));
        let path = dir.join("entry.json");
        let r = sample();
        write_entry(&dir, &path, &to_entry("key A", &r)).unwrap();
        assert_eq!(read_entry(&path, "key A"), Some(r));
        assert_eq!(read_entry(&path, "key B"), None);
        std::fs::write(&path, "{ not json").unwrap();
        assert_eq!(read_entry(&path, "key A"), None);
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn key_depends_on_every_reduction_input() {
        let base = ChassisReduction::default();
        let mut bar = base.clone();
        bar.body.options.stiffening_bar = true;
        let mut fewer = base.clone();
        fewer.max_modes -= 1;
        let mut cut = base.clone();
        cut.cutoff_hz *= 1.5;
        let keys: Vec<u64> = [&base, &bar, &fewer, &cut]
            .iter()
            .map(|r| fnv1a(&key_text(r).unwrap()))
            .collect();
        for i in 0..keys.len() {
            for j in 0..i {
                assert_ne!(keys[i], keys[j], "settings {i} and {j} share a key");
            }
        }
    }
}
