//! A deck body's reduction: interface errors name the point and its GRID, a free-free body is
//! refused as not held (not by the chance sign of a round-off eigenvalue), and the deck's notes
//! (dropped grids, element-shape warnings) come back with the reduction, from the cache too.

use std::collections::BTreeMap;
use std::path::PathBuf;

use engine_mount_chassis::cms::{
    reduce_cached_with_notes, reduce_with_notes, BodySource, BulkDeckBody, CacheOutcome,
    CacheSetting, InterfaceDofs, ModeSelection, ReductionSpec,
};
use engine_mount_chassis::nastran::{deck_digest, DeckOptions};

use crate::plate_deck::{self, plate};

/// The plate held by 1e5 N/m springs at its corners.
fn corner_springs() -> String {
    plate_deck::corner_springs(1e5)
}

/// A reduction spec for `deck` written to a fresh folder, mounts at four interior grids
/// (`mount_c` at `third_mount`).
fn spec(name: &str, deck: &str, third_mount: u32) -> (ReductionSpec, PathBuf) {
    let points = [
        ("mount_a", 1011),
        ("mount_b", 1015),
        ("mount_c", third_mount),
        ("mount_d", 1025),
    ];
    deck_spec(
        &format!("diag-{name}"),
        deck,
        &points,
        ModeSelection::Count(6),
    )
}

/// A reduction spec for `deck` written to a fresh folder (`emc-{name}-…`), its translational
/// interface the named GRIDs, no outputs.
pub(crate) fn deck_spec(
    name: &str,
    deck: &str,
    mounts: &[(&str, u32)],
    selection: ModeSelection,
) -> (ReductionSpec, PathBuf) {
    let dir = std::env::temp_dir().join(format!("emc-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("plate.bdf");
    std::fs::write(&path, deck).unwrap();
    let points: BTreeMap<String, u32> = mounts.iter().map(|(n, g)| (n.to_string(), *g)).collect();
    let spec = ReductionSpec {
        body: BodySource::Deck(BulkDeckBody {
            sha256: deck_digest(&path, &DeckOptions::default()).unwrap(),
            path,
            points: points.clone(),
            include_root: None,
        }),
        interface: points.keys().cloned().collect(),
        interface_dofs: InterfaceDofs::Translations,
        selection,
        outputs: Vec::new(),
        ..ReductionSpec::default()
    };
    (spec, dir)
}

#[test]
fn a_held_plate_reduces_and_its_notes_come_back_from_the_cache() {
    // GRID 5000 is unused (dropped), CQUAD4 18 is warped 0.1 (> Q4_WARP 0.05): both used to
    // refuse the deck; now they are notes.
    let deck = plate(&format!("{}GRID,5000,,3.,3.,3.\n", corner_springs()), 0.04);
    let (spec, dir) = spec("held", &deck, 1021);
    let (reduced, notes) = reduce_with_notes(&spec).unwrap();
    assert_eq!(reduced.n_modes(), 6 + 12);
    let all = notes.join("\n");
    assert!(
        all.contains("1 GRID(s)") && all.contains("GRID 5000"),
        "{all}"
    );
    assert!(all.contains("warped") && all.contains("CQUAD4 18"), "{all}");
    let cache = CacheSetting::Dir(dir.join("cache"));
    let (_, first, stored) = reduce_cached_with_notes(&spec, &cache).unwrap();
    assert!(matches!(first, CacheOutcome::Stored(_)), "{first:?}");
    let (_, second, read) = reduce_cached_with_notes(&spec, &cache).unwrap();
    assert!(matches!(second, CacheOutcome::Hit(_)), "{second:?}");
    assert_eq!((stored, read), (notes.clone(), notes));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn interface_errors_name_the_point_and_its_grid() {
    // mount_c on GRID 1021, held in z by an SPC.
    let deck = plate(&format!("{}SPC1,1,3,1021\n", corner_springs()), 0.0);
    let (s, dir) = spec("spc", &deck, 1021);
    let err = reduce_with_notes(&s).unwrap_err().to_string();
    assert!(
        err.contains("interface point 'mount_c' (GRID 1021) dof uz is constrained"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
    // mount_c on a grid no element references.
    let deck = plate(&format!("{}GRID,5000,,3.,3.,3.\n", corner_springs()), 0.0);
    let (s, dir) = spec("unused", &deck, 5000);
    let err = reduce_with_notes(&s).unwrap_err().to_string();
    assert!(
        err.contains("interface point 'mount_c' is GRID 5000") && err.contains("dropped"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_free_free_body_is_refused_as_not_held() {
    let (s, dir) = spec("free", &plate("", 0.0), 1021);
    let err = reduce_with_notes(&s).unwrap_err().to_string();
    assert!(
        err.contains("the body is not held: 6 reduced mode(s)")
            && err.contains("springs to ground"),
        "{err}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn the_deck_notes_reach_the_body_log_line() {
    use super::bulk_deck::default_vehicle_as_deck;
    use engine_mount_chassis::model::scene::{body, BodyOptions};

    // The procedural chassis as a deck with a leftover GRID: the scene's log line for the body
    // (which the FMU logs at instantiation) carries the note that it was dropped.
    let dir = std::env::temp_dir().join(format!("emc-diag-log-{}", std::process::id()));
    let vehicle = default_vehicle_as_deck(&dir, |deck| {
        deck.replace("ENDDATA\n", "GRID,999999,,9.,9.,9.\nENDDATA\n")
    });
    let options = BodyOptions {
        mode_cutoff_hz: 60.0,
        cache: CacheSetting::Disabled,
        ..BodyOptions::default()
    };
    let (_, notes) = body(&vehicle, &options).unwrap();
    let note = &notes[0];
    assert!(
        note.contains("bulk data deck") && note.contains("1 GRID(s)") && note.contains("999999"),
        "{note}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
