//! A deck's own modal damping: the `TABDMP1` its case control names with `SDAMPING` reaches
//! every mode of the reduced body (a step and a `SKIP` pair included), survives the cache, and
//! bad damping input is refused naming the card, its id and the deck line. (The independent
//! check, a deck written by pyNastran through the body FMU, is `python/tests/test_bulk_deck.py`.)

use std::path::PathBuf;

use engine_mount_chassis::cms::{
    reduce_cached_with_notes, reduce_with_notes, CacheOutcome, CacheSetting, ModeSelection,
    ReductionSpec,
};

use crate::plate_deck;

/// The held plate with a case control section (`control`) and `extra` bulk cards, written to a
/// fresh folder, as a reduction spec keeping every fixed-interface mode below 1 kHz.
fn deck_spec(name: &str, control: &str, extra: &str) -> (ReductionSpec, PathBuf) {
    let bulk = plate_deck::plate(&format!("{}{extra}", plate_deck::corner_springs(1e5)), 0.0);
    let mounts = [("mount_a", 1011), ("mount_b", 1015), ("mount_c", 1021)];
    crate::deck_diagnostics::deck_spec(
        &format!("deck-damping-{name}"),
        &format!("SOL 103\nCEND\n{control}{bulk}"),
        &mounts,
        ModeSelection::CutoffHz(1000.0),
    )
}

/// The table of the test written out by hand: G 0.04 up to 50 Hz, a step to G 0.08 there, G
/// 0.16 at 400 Hz (the pair at 300 Hz skipped), held beyond.
fn expected_ratio(hz: f64) -> f64 {
    let g = if hz < 50.0 {
        0.04
    } else if hz == 50.0 {
        0.06
    } else if hz < 400.0 {
        0.08 + (hz - 50.0) / 350.0 * 0.08
    } else {
        0.16
    };
    g / 2.0
}

const TABLE: &str = "TABDMP1,5,G\n,0.,.04,50.,.04,50.,.08,SKIP,SKIP\n,400.,.16,ENDT\n";

#[test]
fn the_tabdmp1_sdamping_names_reaches_every_mode_and_the_cache() {
    let (spec, dir) = deck_spec(
        "reaches",
        "SUBCASE 1\n  SDAMPING = 5\n",
        &format!("{TABLE}TABDMP1,6,CRIT\n,0.,.5,ENDT\n"),
    );
    let (reduced, _) = reduce_with_notes(&spec).unwrap();
    let own = reduced.own_damping.as_ref().expect("the deck's table");
    assert!(own.source.contains("TABDMP1 5"), "{}", own.source);
    let hz: Vec<f64> = reduced
        .omega
        .iter()
        .map(|w| w / (2.0 * std::f64::consts::PI))
        .collect();
    assert!(hz.iter().any(|f| *f < 50.0) && hz.iter().any(|f| *f > 400.0));
    for (f, z) in hz.iter().zip(&reduced.zeta) {
        assert!((z - expected_ratio(*f)).abs() < 1e-15, "{f} Hz: {z}");
    }
    let cache = CacheSetting::Dir(dir.join("cache"));
    let (_, first, _) = reduce_cached_with_notes(&spec, &cache).unwrap();
    assert!(matches!(first, CacheOutcome::Stored(_)), "{first:?}");
    let (cached, second, _) = reduce_cached_with_notes(&spec, &cache).unwrap();
    assert!(matches!(second, CacheOutcome::Hit(_)), "{second:?}");
    assert_eq!(cached.own_damping, reduced.own_damping);
    // Without SDAMPING the tables are read and not used.
    let (unused, dir2) = deck_spec("unused", "", TABLE);
    assert!(reduce_with_notes(&unused).unwrap().0.own_damping.is_none());
    let _ = std::fs::remove_dir_all(&dir);
    let _ = std::fs::remove_dir_all(&dir2);
}

#[test]
fn bad_damping_input_is_refused_naming_card_id_and_line() {
    // The deck: SOL, CEND, the control line(s), then BEGIN BULK at line 4 (or 5), the plate's
    // 2 + 28 + 18 cards and 12 springs; the extra cards start at line 65.
    let cases: [(&str, &str, &[&str]); 9] = [
        (
            "SDAMPING = 9\n",
            TABLE,
            &["line 3", "SDAMPING = 9 names no TABDMP1", "ids: 5"],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,KDAMP\n,0.,.04,ENDT\n",
            &[
                "line 65",
                "TABDMP1",
                "TYPE",
                "TABDMP1 5",
                "'KDAMP' is not handled",
            ],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,CRIT\n,0.,.04,100.,-.01,ENDT\n",
            &[
                "line 66",
                "TABDMP1 5 (card at line 65)",
                "point 1",
                "CRIT value -0.01",
            ],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,CRIT\n,0.,.04,100.,.05,80.,.06,ENDT\n",
            &["line 66", "TABDMP1 5", "point 2", "below the one before it"],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,Q\n,0.,0.,ENDT\n",
            &["TABDMP1 5", "point 0", "Q value 0"],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,CRIT,0\n,0.,.04,ENDT\n",
            &["line 65", "TABDMP1 5", "FLAT = 0"],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,CRIT\n,0.,.04,100.,.05\n",
            &["line 65", "TABDMP1 5", "no ENDT"],
        ),
        (
            "SDAMPING = 5\n",
            "TABDMP1,5,CRIT\n,0.,.04,ENDT,,7.\n",
            &["line 66", "TABDMP1 5", "after the end of the table"],
        ),
        (
            // A frequency without its value: the 100 Hz point must not vanish silently.
            "SDAMPING = 5\n",
            "TABDMP1,10,CRIT\n,0.,.04,100.,ENDT\n",
            &[
                "line 66",
                "TABDMP1 10",
                "the frequency 100 has no damping value before ENDT",
            ],
        ),
    ];
    for (k, (control, cards, says)) in cases.iter().enumerate() {
        let (spec, dir) = deck_spec(&format!("bad{k}"), control, cards);
        let e = reduce_with_notes(&spec).unwrap_err().to_string();
        println!("{e}");
        for s in *says {
            assert!(e.contains(s), "case {k}: '{s}' not in {e}");
        }
        assert!(e.contains("plate.bdf"), "case {k}: {e}");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
