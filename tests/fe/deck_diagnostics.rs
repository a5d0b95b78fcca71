//! Diagnostics of a user's deck: messages name GRID and element ids (with the line), unused
//! GRIDs are dropped with a note, poor element shapes are warnings as in Nastran's GEOMCHECK
//! while invalid ones are refused, and springs and bushes hold their grids.

use engine_mount_chassis::fe::checks::{check_mesh, check_mesh_named, CheckLimits};
use engine_mount_chassis::nastran::{parse_str, DeckNames, NastranBody};

#[path = "../common/plate_deck.rs"]
mod plate_deck;
use plate_deck::plate;

fn checked(body: &NastranBody) -> Result<Vec<String>, String> {
    check_mesh_named(
        &body.mesh,
        &CheckLimits::nastran_deck(),
        &DeckNames::new(body),
    )
    .map_err(|e| e.to_string())
}

#[test]
fn an_unused_grid_is_dropped_with_a_note_naming_it() {
    let springs = plate_deck::corner_springs(1e6);
    let body = parse_str(&plate(
        &format!("{springs}GRID,5000,,3.,3.,3.\nGRID,5001,,4.,3.,3.\n"),
        0.0,
    ))
    .unwrap();
    assert_eq!(body.unused_grids, vec![5000, 5001]);
    let note = body.notes.join("\n");
    assert!(
        note.contains("2 GRID(s)") && note.contains("GRID 5000, 5001"),
        "{note}"
    );
    let node = body.node(5000).unwrap();
    let held: Vec<usize> = (0..6)
        .filter(|d| body.mesh.constraints.contains(&(node, *d)))
        .collect();
    assert_eq!(held, vec![0, 1, 2, 3, 4, 5], "no DOFs on the dropped grid");
    assert_eq!(checked(&body), Ok(Vec::new()));
    // Before, the same grid refused the deck naming an internal index; the mesh check still
    // refuses an unconnected node of a mesh built in code.
    let mut bare = body.mesh.clone();
    bare.constraints.retain(|&(k, _)| k != node);
    let err = check_mesh(&bare, &CheckLimits::default())
        .unwrap_err()
        .to_string();
    assert!(
        err.contains(&format!("node {node}: not connected")),
        "{err}"
    );
}

#[test]
fn messages_name_the_grid_and_the_card_with_its_line() {
    let springs = plate_deck::corner_springs(1e6);
    // GRID 5000 carries only a CONM2; CQUAD4 40 has a reflex corner (inverted Jacobian).
    let extra = format!(
        "{springs}GRID,5000,,3.,3.,3.\nCONM2,77,5000,,1.\n\
         GRID,6000,,0.,1.,0.\nGRID,6001,,0.1,1.,0.\nGRID,6002,,0.02,1.02,0.\nGRID,6003,,0.,1.1,0.\n\
         CQUAD4,40,1,6000,6001,6002,6003\nCELAS2,913,1.e6,6000,3\n"
    );
    let deck = plate(&extra, 0.0);
    let line = deck
        .lines()
        .position(|l| l.starts_with("CQUAD4,40"))
        .unwrap()
        + 1;
    let body = parse_str(&deck).unwrap();
    let err = checked(&body).unwrap_err();
    assert!(
        err.contains("GRID 5000: carries only point masses"),
        "{err}"
    );
    assert!(
        err.contains(&format!("CQUAD4 40 (line {line}): inverted or degenerate")),
        "{err}"
    );
    assert!(!err.contains("node "), "internal indices leak: {err}");
}

#[test]
fn poor_shapes_of_a_deck_are_warnings_and_the_worst_element_is_named() {
    // GRID 1036 raised 0.04 m: CQUAD4 18 has warp 0.1 (limit 0.05 as GEOMCHECK Q4_WARP).
    let body = parse_str(&plate(&plate_deck::corner_springs(1e6), 0.04)).unwrap();
    let notes = checked(&body).unwrap();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(
        notes[0].contains("1 element(s) warped") && notes[0].contains("worst CQUAD4 18 (line"),
        "{notes:?}"
    );
    // Our own (procedural) limits refuse it, naming the mesh index.
    let err = check_mesh(&body.mesh, &CheckLimits::default())
        .unwrap_err()
        .to_string();
    assert!(err.contains("shell 17: warped"), "{err}");
    // A mild warp (0.025) that the strict limit (0.01) refused passes a deck silently.
    let mild = parse_str(&plate(&plate_deck::corner_springs(1e6), 0.01)).unwrap();
    assert_eq!(checked(&mild), Ok(Vec::new()));
    assert!(check_mesh(&mild.mesh, &CheckLimits::default()).is_err());
}

#[test]
fn a_tapered_quad_is_counted_and_named() {
    let springs = plate_deck::corner_springs(1e6);
    // A trapezoid with sides 0.6 and 0.1 m: taper 0.71 beyond the GEOMCHECK default 0.5.
    let extra = format!(
        "{springs}GRID,6000,,1.2,0.,0.\nGRID,6001,,0.75,-0.1,0.\nGRID,6002,,0.65,-0.1,0.\n\
         CQUAD4,41,1,1006,6000,6001,6002\n"
    );
    let body = parse_str(&plate(&extra, 0.0)).unwrap();
    let notes = checked(&body).unwrap();
    let all = notes.join("\n");
    assert!(
        all.contains("tapered") && all.contains("CQUAD4 41"),
        "{all}"
    );
}

#[test]
fn grids_held_only_by_springs_or_bushes_are_connected() {
    let springs = plate_deck::corner_springs(1e6);
    // A wheel-centre grid on a CBUSH to the plate and a grid on a CELAS2 to ground, each with
    // a mass: both were refused as carrying "only masses/springs".
    let extra = format!(
        "{springs}GRID,7000,,0.3,0.1,-0.2\nPBUSH,3,K,1.e5,1.e5,1.e5,1.e3,1.e3,1.e3\n\
         CBUSH,50,3,7000,1012,,,,0\nCONM2,51,7000,,20.\n\
         GRID,7001,,0.5,0.5,0.5\nCELAS2,52,1.e4,7001,3\nCONM2,53,7001,,1.\n"
    );
    let body = parse_str(&plate(&extra, 0.0)).unwrap();
    assert_eq!(checked(&body), Ok(Vec::new()));
    assert!(body.unused_grids.is_empty());
}

#[test]
fn an_unknown_card_lists_every_supported_card() {
    let err = parse_str(&plate("CTRIA6,1,1,1000,1001,1010\n", 0.0))
        .unwrap_err()
        .to_string();
    for card in [
        "MAT2", "MAT8", "PSOLID", "CBUSH", "CONM1", "CORD2S", "EIGRL",
    ] {
        assert!(err.contains(card), "{card} missing: {err}");
    }
}
