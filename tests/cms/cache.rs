//! The reduction cache: hits return the identical reduction, any changed input misses, corrupt
//! or foreign entries are rebuilt, unwritable directories do not fail the reduction, and
//! concurrent callers reduce once (the others wait on the entry's lock) and leave one complete
//! entry.

use std::path::{Path, PathBuf};

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::cms::{
    reduce, reduce_cached, BodySource, CacheOutcome, CacheSetting, DampingTable, ModeSelection,
    ReductionSpec,
};

/// A cheap reduction (constraint modes only) keeps these tests fast; the cache does not care.
fn spec() -> ReductionSpec {
    ReductionSpec {
        selection: ModeSelection::Count(0),
        ..ReductionSpec::default()
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("cms-cache-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

fn stored_path(outcome: &CacheOutcome) -> &Path {
    match outcome {
        CacheOutcome::Stored(p) => p,
        other => panic!("expected a stored entry, got {other:?}"),
    }
}

#[test]
fn second_call_hits_and_returns_the_identical_reduction() {
    let dir = temp_dir("hit");
    let setting = CacheSetting::Dir(dir.clone());
    let (built, first) = reduce_cached(&spec(), &setting).unwrap();
    let path = stored_path(&first).to_path_buf();
    assert!(path.starts_with(&dir));
    let (cached, second) = reduce_cached(&spec(), &setting).unwrap();
    assert_eq!(second, CacheOutcome::Hit(path));
    // Bit-identical floats: serde_json's float_roundtrip.
    assert_eq!(cached, built);
    assert_eq!(cached, reduce(&spec()).unwrap());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn any_changed_input_misses_the_cache() {
    let dir = temp_dir("miss");
    let setting = CacheSetting::Dir(dir.clone());
    let (base, first) = reduce_cached(&spec(), &setting).unwrap();
    let base_path = stored_path(&first).to_path_buf();

    let mut stiffer = spec();
    stiffer.body = BodySource::Procedural(Box::new(ChassisConfig {
        body_stiffness_scale: ChassisConfig::default().body_stiffness_scale * (1.0 + 1e-12),
        ..ChassisConfig::default()
    }));
    let mut damped = spec();
    damped.damping = DampingTable::uniform(0.02);
    let mut outputs = spec();
    outputs.outputs.push("wheel_front_left".into());
    for (what, changed) in [
        ("stiffness", stiffer),
        ("damping", damped),
        ("outputs", outputs),
    ] {
        let (reduced, outcome) = reduce_cached(&changed, &setting).unwrap();
        let path = stored_path(&outcome);
        assert_ne!(path, base_path, "{what}: same entry as the base spec");
        assert_eq!(reduced, reduce(&changed).unwrap(), "{what}");
    }
    let (again, outcome) = reduce_cached(&spec(), &setting).unwrap();
    assert_eq!(outcome, CacheOutcome::Hit(base_path));
    assert_eq!(again, base);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn corrupt_and_foreign_entries_are_rebuilt_and_replaced() {
    let dir = temp_dir("corrupt");
    let setting = CacheSetting::Dir(dir.clone());
    let (good, first) = reduce_cached(&spec(), &setting).unwrap();
    let path = stored_path(&first).to_path_buf();

    // Truncated (a writer killed half-way without the atomic rename would leave this).
    let text = std::fs::read_to_string(&path).unwrap();
    std::fs::write(&path, &text[..text.len() / 2]).unwrap();
    let (rebuilt, outcome) = reduce_cached(&spec(), &setting).unwrap();
    match &outcome {
        CacheOutcome::Replaced { path: p, reason } => {
            assert_eq!(p, &path);
            assert!(reason.contains("corrupt"), "{reason}");
        }
        other => panic!("expected a replaced entry, got {other:?}"),
    }
    assert_eq!(rebuilt, good);
    assert_eq!(
        reduce_cached(&spec(), &setting).unwrap().1,
        CacheOutcome::Hit(path.clone())
    );

    // Foreign: a valid entry of another spec under this spec's name (as a hash collision would).
    let mut other = spec();
    other.damping = DampingTable::uniform(0.5);
    let (_, o) = reduce_cached(&other, &setting).unwrap();
    std::fs::copy(stored_path(&o), &path).unwrap();
    let (rebuilt, outcome) = reduce_cached(&spec(), &setting).unwrap();
    match &outcome {
        CacheOutcome::Replaced { reason, .. } => {
            assert!(reason.contains("different inputs"), "{reason}")
        }
        other => panic!("expected a replaced entry, got {other:?}"),
    }
    assert_eq!(rebuilt, good);

    // Valid JSON, right key, but damaged numbers: the content no longer matches its checksum.
    let text = std::fs::read_to_string(&path).unwrap();
    let mut value: serde_json::Value = serde_json::from_str(&text).unwrap();
    value["reduced"]["omega"][0] = serde_json::json!(-1.0);
    std::fs::write(&path, value.to_string()).unwrap();
    match reduce_cached(&spec(), &setting).unwrap().1 {
        CacheOutcome::Replaced { reason, .. } => assert!(reason.contains("checksum"), "{reason}"),
        other => panic!("expected a replaced entry, got {other:?}"),
    }
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn unwritable_cache_and_disabled_cache_still_reduce() {
    let expected = reduce(&spec()).unwrap();
    // A directory below a regular file cannot be created, even by root.
    let blocker = temp_dir("blocker");
    std::fs::write(&blocker, b"not a directory").unwrap();
    let (r, outcome) = reduce_cached(&spec(), &CacheSetting::Dir(blocker.join("cache"))).unwrap();
    assert_eq!(r, expected);
    match outcome {
        CacheOutcome::NotStored { reason } => assert!(reason.contains("creating"), "{reason}"),
        other => panic!("expected NotStored, got {other:?}"),
    }
    let _ = std::fs::remove_file(&blocker);
    let (r, outcome) = reduce_cached(&spec(), &CacheSetting::Disabled).unwrap();
    assert_eq!(outcome, CacheOutcome::Disabled);
    assert_eq!(r, expected);
}

#[test]
fn concurrent_writers_leave_one_complete_entry() {
    let dir = temp_dir("concurrent");
    let setting = CacheSetting::Dir(dir.clone());
    let results: Vec<_> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..3)
            .map(|_| s.spawn(|| reduce_cached(&spec(), &setting).unwrap()))
            .collect();
        handles.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (r, _) in &results {
        assert_eq!(r, &results[0].0);
    }
    // One built and stored it; the others waited on its lock and read it.
    let stored = results
        .iter()
        .filter(|(_, o)| matches!(o, CacheOutcome::Stored(_)))
        .count();
    let hits = results
        .iter()
        .filter(|(_, o)| matches!(o, CacheOutcome::Hit(_)))
        .count();
    assert_eq!((stored, hits), (1, 2), "{results:?}");
    let files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|name| !name.ends_with(".lock"))
        .collect();
    assert_eq!(files.len(), 1, "temporary files left behind: {files:?}");
    let (r, outcome) = reduce_cached(&spec(), &setting).unwrap();
    assert!(matches!(outcome, CacheOutcome::Hit(_)), "{outcome:?}");
    assert_eq!(r, results[0].0);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn invalid_spec_is_an_error_not_a_cache_entry() {
    let dir = temp_dir("invalid");
    let mut bad = spec();
    bad.damping.points[3][1] = f64::NAN;
    let e = reduce_cached(&bad, &CacheSetting::Dir(dir.clone()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("point 3"), "{e}");
    let mut bad = spec();
    bad.outputs.push("no_such_node".into());
    let e = reduce_cached(&bad, &CacheSetting::Dir(dir.clone()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no_such_node"), "{e}");
    assert!(std::fs::read_dir(&dir).map_or(true, |mut d| d.next().is_none()));
}
