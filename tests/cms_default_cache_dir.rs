//! The default cache location follows XDG_CACHE_HOME. Alone in its own test binary because it
//! sets an environment variable.

use engine_mount_chassis::cms::{
    reduce_cached, CacheOutcome, CacheSetting, ModeSelection, ReductionSpec,
};

#[test]
fn default_cache_lives_under_xdg_cache_home() {
    let base = std::env::temp_dir().join(format!("cms-xdg-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&base);
    std::env::set_var("XDG_CACHE_HOME", &base);
    let spec = ReductionSpec {
        selection: ModeSelection::Count(0),
        ..ReductionSpec::default()
    };
    let (_, outcome) = reduce_cached(&spec, &CacheSetting::Default).unwrap();
    match outcome {
        CacheOutcome::Stored(path) => {
            assert!(
                path.starts_with(base.join("engine_mount_chassis")),
                "{}",
                path.display()
            )
        }
        other => panic!("expected a stored entry, got {other:?}"),
    }
    let (_, outcome) = reduce_cached(&spec, &CacheSetting::Default).unwrap();
    assert!(matches!(outcome, CacheOutcome::Hit(_)), "{outcome:?}");
    let _ = std::fs::remove_dir_all(&base);
}
