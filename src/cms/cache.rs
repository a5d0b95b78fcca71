//! On-disk cache of reductions, so that a second instantiation with the same inputs is fast.
//!
//! Entries live in `$XDG_CACHE_HOME/engine_mount_chassis` (else `~/.cache/engine_mount_chassis`)
//! or a directory the caller names. An entry is named by a hash of its key and stores the full
//! key: the format version, the crate version, a fingerprint of the source code of the FE
//! generator and the reduction, and the canonical JSON of the [`ReductionSpec`].
//! It is used only if the stored key equals the wanted one and the data is consistent and
//! finite; anything else (corrupt, truncated, foreign, older format) is ignored, rebuilt and
//! replaced. Entries are written to a temporary file in the same directory and renamed into
//! place, so concurrent processes see either no entry or a complete one; a failed write never
//! fails the reduction.
//!
//! A reduction about to be built takes an exclusive lock on the entry's lock file
//! (`cms-….lock` beside it) and looks for the entry again once it holds it. So processes and
//! threads that want the same body at the same time (the instances of a Dask worker with
//! several threads, the workers of one machine) reduce it once: the first builds and stores it,
//! the others wait and read it. Where no lock can be taken (a read-only directory, a file
//! system without locks) each reduces on its own, as before.

use std::fs;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use serde::{Deserialize, Serialize};

use super::error::CmsError;
use super::hash::sha256_hex;
use super::reduce::reduce_with_notes;
use super::reduced::ReducedChassis;
use super::spec::ReductionSpec;

/// Version of the entry layout and of the reduction algorithm; bump it whenever the entry
/// format, the reduction or the FE generator changes results for the same spec.
pub const FORMAT_VERSION: u32 = 2;

const CACHE_SUBDIR: &str = "engine_mount_chassis";

/// Where reductions are cached.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheSetting {
    /// The user cache directory (`$XDG_CACHE_HOME` or `~/.cache`), subdirectory
    /// `engine_mount_chassis`.
    Default,
    /// This directory (created if missing).
    Dir(PathBuf),
    /// No cache: always reduce.
    Disabled,
}

/// What [`reduce_cached`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum CacheOutcome {
    /// A valid entry was read from this file.
    Hit(PathBuf),
    /// No entry existed; the reduction was built and stored in this file.
    Stored(PathBuf),
    /// The existing entry was unusable (`reason`); the reduction was rebuilt and the entry
    /// replaced.
    Replaced {
        /// The entry's file.
        path: PathBuf,
        /// Why the old entry was rejected.
        reason: String,
    },
    /// The reduction was built but could not be stored (`reason`), e.g. a read-only directory.
    NotStored {
        /// What failed.
        reason: String,
    },
    /// Caching is disabled; the reduction was built.
    Disabled,
}

#[derive(Serialize, Deserialize)]
struct Entry {
    format: u32,
    key: String,
    /// SHA-256 of the reduction's JSON (and of the notes, if any): an entry edited after it
    /// was written is not served.
    checksum: String,
    reduced: ReducedChassis,
    /// The notes on the body ([`crate::cms::Reduction::notes`]): a cache hit logs them too.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    notes: Vec<String>,
}

impl Entry {
    fn new(key: String, reduced: ReducedChassis, notes: Vec<String>) -> Result<Self, String> {
        Ok(Self {
            format: FORMAT_VERSION,
            key,
            checksum: checksum(&reduced, &notes)?,
            reduced,
            notes,
        })
    }
}

fn checksum(reduced: &ReducedChassis, notes: &[String]) -> Result<String, String> {
    let mut json = serde_json::to_string(reduced).map_err(|e| format!("serialising: {e}"))?;
    if !notes.is_empty() {
        json += &serde_json::to_string(notes).map_err(|e| format!("serialising: {e}"))?;
    }
    Ok(sha256_hex(json.as_bytes()))
}

/// The source of every file whose code turns a spec into a reduction (elements, decks, the
/// procedural chassis, eigensolvers, reduction), gathered by `build.rs` from their folders.
/// Hashing it into the key means an edited generator or solver can never be served a reduction
/// computed by the old code, even without a bump of [`FORMAT_VERSION`].
const ALGORITHM_SOURCES: &str = include_str!(concat!(env!("OUT_DIR"), "/algorithm_sources.txt"));

/// Fingerprint of [`ALGORITHM_SOURCES`], computed once per process.
fn algorithm_fingerprint() -> &'static str {
    static FINGERPRINT: OnceLock<String> = OnceLock::new();
    FINGERPRINT.get_or_init(|| sha256_hex(ALGORITHM_SOURCES.as_bytes()))
}

/// The full cache key of `spec`: the format version, the fingerprint of the code and every
/// input of the reduction.
fn key_text(spec: &ReductionSpec) -> Result<String, CmsError> {
    Ok(format!(
        "engine_mount_chassis cms format {FORMAT_VERSION} crate {} code {}\n{}",
        env!("CARGO_PKG_VERSION"),
        algorithm_fingerprint(),
        spec.canonical_json()?
    ))
}

/// The user's cache folder for this crate: `$XDG_CACHE_HOME` or `~/.cache` on Linux,
/// `%LOCALAPPDATA%` on Windows (the `directories` crate's convention).
fn default_dir() -> Option<PathBuf> {
    directories::BaseDirs::new().map(|d| d.cache_dir().join(CACHE_SUBDIR))
}

/// Checks that a loaded reduction is complete and finite.
fn check_consistent(r: &ReducedChassis) -> Result<(), String> {
    let n = r.omega.len();
    if n == 0 {
        return Err("no modes".into());
    }
    if r.zeta.len() != n {
        return Err(format!("{} damping ratios for {n} modes", r.zeta.len()));
    }
    if let Some(k) = r.omega.iter().position(|w| !(w.is_finite() && *w > 0.0)) {
        return Err(format!("omega[{k}] = {} is not finite and > 0", r.omega[k]));
    }
    if r.omega.windows(2).any(|w| w[1] < w[0]) {
        return Err("omega is not ascending".into());
    }
    if let Some(k) = r.zeta.iter().position(|z| !(z.is_finite() && *z >= 0.0)) {
        return Err(format!("zeta[{k}] = {} is not finite and >= 0", r.zeta[k]));
    }
    if r.points.is_empty() {
        return Err("no recovery points".into());
    }
    for p in &r.points {
        if p.shape.len() != n {
            return Err(format!(
                "point '{}' has {} rows for {n} modes",
                p.name,
                p.shape.len()
            ));
        }
        if p.position
            .iter()
            .chain(p.shape.iter().flatten())
            .any(|v| !v.is_finite())
        {
            return Err(format!("point '{}' has a non-finite value", p.name));
        }
    }
    Ok(())
}

/// Reads the entry at `path` if it holds a valid reduction for `key`.
fn load(path: &Path, key: &str) -> Result<(ReducedChassis, Vec<String>), String> {
    let text = crate::text_file::read_limited(path, crate::text_file::DATA_LIMIT)
        .map_err(|e| format!("unreadable: {e}"))?;
    let entry: Entry = serde_json::from_str(&text).map_err(|e| format!("corrupt: {e}"))?;
    if entry.format != FORMAT_VERSION {
        return Err(format!(
            "format {} (expected {FORMAT_VERSION})",
            entry.format
        ));
    }
    if entry.key != key {
        return Err("written for different inputs".into());
    }
    if checksum(&entry.reduced, &entry.notes)? != entry.checksum {
        return Err("altered after it was written (checksum mismatch)".into());
    }
    check_consistent(&entry.reduced).map_err(|e| format!("inconsistent: {e}"))?;
    Ok((entry.reduced, entry.notes))
}

/// Writes `entry` to `path` atomically: a unique temporary file in the same directory, then a
/// rename over the target.
fn store(path: &Path, entry: &Entry) -> Result<(), String> {
    let dir = path
        .parent()
        .ok_or_else(|| format!("{} has no parent directory", path.display()))?;
    fs::create_dir_all(dir).map_err(|e| format!("creating {}: {e}", dir.display()))?;
    let text = serde_json::to_string(entry).map_err(|e| format!("serialising: {e}"))?;
    let written = (|| {
        // The temporary file is removed by tempfile if anything below fails.
        let mut f = tempfile::NamedTempFile::new_in(dir)?;
        f.write_all(text.as_bytes())?;
        f.as_file().sync_all()?;
        f.persist(path).map_err(|e| e.error)?;
        Ok::<_, std::io::Error>(())
    })();
    written.map_err(|e| format!("writing {}: {e}", path.display()))
}

/// An exclusive lock on `path` (created if missing), released when the file is dropped; `None`
/// where none can be taken.
fn lock(path: &Path) -> Option<fs::File> {
    fs::create_dir_all(path.parent()?).ok()?;
    let file = fs::OpenOptions::new()
        .create(true)
        .truncate(false)
        .write(true)
        .open(path)
        .ok()?;
    file.lock().ok()?;
    Some(file)
}

/// [`reduce`](super::reduce::reduce) through the cache selected by `cache`.
pub fn reduce_cached(
    spec: &ReductionSpec,
    cache: &CacheSetting,
) -> Result<(ReducedChassis, CacheOutcome), CmsError> {
    reduce_cached_with_notes(spec, cache).map(|(reduced, outcome, _)| (reduced, outcome))
}

/// [`reduce_cached`] with the notes on the body for the log ([`crate::cms::Reduction::notes`]),
/// kept in the cache entry so that a cache hit reports them as the reduction did.
pub fn reduce_cached_with_notes(
    spec: &ReductionSpec,
    cache: &CacheSetting,
) -> Result<(ReducedChassis, CacheOutcome, Vec<String>), CmsError> {
    let dir = match cache {
        CacheSetting::Disabled => {
            let (reduced, notes) = reduce_with_notes(spec)?;
            return Ok((reduced, CacheOutcome::Disabled, notes));
        }
        CacheSetting::Dir(d) => Some(d.clone()),
        CacheSetting::Default => default_dir(),
    };
    spec.validate()?;
    let key = key_text(spec)?;
    let Some(dir) = dir else {
        let (reduced, notes) = reduce_with_notes(spec)?;
        let reason = "no cache directory: neither XDG_CACHE_HOME nor HOME is an absolute path";
        return Ok((
            reduced,
            CacheOutcome::NotStored {
                reason: reason.into(),
            },
            notes,
        ));
    };
    let name = format!("cms-{}", &sha256_hex(key.as_bytes())[..16]);
    let path = dir.join(format!("{name}.json"));
    let look = |path: PathBuf| {
        if !path.exists() {
            return Err(None);
        }
        match load(&path, &key) {
            Ok((reduced, notes)) => Ok((reduced, CacheOutcome::Hit(path), notes)),
            Err(reason) => Err(Some(reason)),
        }
    };
    if let Ok(hit) = look(path.clone()) {
        return Ok(hit);
    }
    // Held until this reduction is stored: whoever waited on it then finds the entry.
    let lock_path = dir.join(format!("{name}.lock"));
    let _lock = lock(&lock_path);
    let rejected = match look(path.clone()) {
        Ok(hit) => return Ok(hit),
        Err(rejected) => rejected,
    };
    let (reduced, notes) = reduce_with_notes(spec).inspect_err(|_| {
        // A spec that cannot be reduced leaves no file behind. A waiter still holding the
        // removed file's lock may then reduce beside a newcomer: twice the work, never a
        // wrong entry.
        let _ = fs::remove_file(&lock_path);
    })?;
    let entry = match Entry::new(key, reduced.clone(), notes.clone()) {
        Ok(entry) => entry,
        Err(reason) => return Ok((reduced, CacheOutcome::NotStored { reason }, notes)),
    };
    let outcome = match (store(&path, &entry), rejected) {
        (Ok(()), None) => CacheOutcome::Stored(path),
        (Ok(()), Some(reason)) => CacheOutcome::Replaced { path, reason },
        (Err(reason), _) => CacheOutcome::NotStored { reason },
    };
    Ok((entry.reduced, outcome, entry.notes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cms::reduced::RecoveryPoint;

    fn tiny() -> ReducedChassis {
        ReducedChassis {
            omega: vec![10.0, 20.0],
            zeta: vec![0.01, 0.01],
            points: vec![RecoveryPoint {
                name: "p".into(),
                node: 3,
                position: [0.0, 1.0, 2.0],
                shape: vec![[1.0; 6], [2.0; 6]],
            }],
            cutoff_hz: None,
            own_damping: None,
        }
    }

    #[test]
    fn consistency_check_names_the_defect() {
        assert!(check_consistent(&tiny()).is_ok());
        let mut r = tiny();
        r.omega[1] = 5.0;
        assert!(check_consistent(&r).unwrap_err().contains("ascending"));
        let mut r = tiny();
        r.points[0].shape.pop();
        assert!(check_consistent(&r).unwrap_err().contains("'p' has 1 rows"));
        let mut r = tiny();
        r.points[0].shape[0][4] = f64::INFINITY;
        assert!(check_consistent(&r).unwrap_err().contains("non-finite"));
        let mut r = tiny();
        r.zeta.push(0.1);
        assert!(check_consistent(&r)
            .unwrap_err()
            .contains("3 damping ratios"));
    }

    #[test]
    fn store_then_load_round_trips_and_rejects_other_keys() {
        let dir = std::env::temp_dir().join(format!("cms-cache-unit-{}", std::process::id()));
        let path = dir.join("entry.json");
        let notes = vec!["3 GRID(s) … were dropped".to_string()];
        let entry = Entry::new("k1".into(), tiny(), notes.clone()).unwrap();
        store(&path, &entry).unwrap();
        assert_eq!(load(&path, "k1").unwrap(), (tiny(), notes));
        assert!(load(&path, "k2").unwrap_err().contains("different inputs"));
        // a reduction edited in place (still valid JSON, still consistent) is refused
        let mut altered = Entry::new("k1".into(), tiny(), Vec::new()).unwrap();
        altered.reduced.omega[0] *= 1.01;
        store(&path, &altered).unwrap();
        assert!(load(&path, "k1").unwrap_err().contains("checksum"));
        let mut renoted = Entry::new("k1".into(), tiny(), Vec::new()).unwrap();
        renoted.notes.push("edited".into());
        store(&path, &renoted).unwrap();
        assert!(load(&path, "k1").unwrap_err().contains("checksum"));
        fs::write(&path, "{\"format\": 1, \"key\": \"k1\", \"reduced\": {").unwrap();
        assert!(load(&path, "k1").unwrap_err().contains("corrupt"));
        let old = Entry {
            format: FORMAT_VERSION + 1,
            ..entry
        };
        store(&path, &old).unwrap();
        assert!(load(&path, "k1").unwrap_err().contains("format"));
        let leftovers = fs::read_dir(&dir).unwrap().count();
        assert_eq!(leftovers, 1, "temporary files must not remain");
        let _ = fs::remove_dir_all(&dir);
    }
}
