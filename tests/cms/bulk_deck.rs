//! A user's body from a bulk data deck runs through the same reduction and coupled model as the
//! procedural one: the procedural chassis written as a deck and named by GRID ids gives the same
//! coupled engine-in-body modes (paper Table 1, middle column) as the procedural chassis itself.

use std::collections::BTreeMap;

use engine_mount_chassis::cms::CacheSetting;
use engine_mount_chassis::fe::chassis::Chassis;
use engine_mount_chassis::fe::chassis_config::ChassisConfig;
use engine_mount_chassis::fe::nastran::write_bulk_deck;
use engine_mount_chassis::model::scene::{build, BodyOptions, SceneKind};
use engine_mount_chassis::model::{BodyConfig, VehicleConfig};

fn modes(vehicle: &VehicleConfig) -> Vec<f64> {
    let options = BodyOptions {
        mode_cutoff_hz: 100.0,
        cache: CacheSetting::Disabled,
        ..BodyOptions::default()
    };
    let mut model = build(vehicle, SceneKind::Body, &options)
        .expect("scene")
        .model;
    model
        .set_crank_speed(0.0, 0.0, 0.0)
        .expect("engine at rest");
    let y = model.static_equilibrium(0.0).expect("statics");
    let mut f: Vec<f64> = model
        .modes(&y)
        .expect("modes")
        .iter()
        .map(|m| m.frequency_hz)
        .collect();
    f.truncate(20);
    f
}

#[test]
fn the_procedural_chassis_as_a_bulk_deck_gives_the_same_coupled_modes() {
    let procedural = VehicleConfig::default();
    let chassis = Chassis::build(&ChassisConfig::default()).expect("chassis");
    let dir = std::env::temp_dir().join(format!("emc-deck-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("chassis.bdf");
    std::fs::write(&path, write_bulk_deck(&chassis.mesh).expect("deck")).unwrap();
    // The deck's GRID ids are node index + 1; name the points the mounts and outputs use.
    let mut names: Vec<String> = procedural
        .mounts
        .iter()
        .filter_map(|m| m.body_node.clone())
        .collect();
    names.extend(procedural.outputs.iter().cloned());
    let points: BTreeMap<String, u32> = names
        .iter()
        .map(|n| (n.clone(), chassis.node(n).expect("named node") as u32 + 1))
        .collect();
    let mut from_deck = procedural.clone();
    from_deck.body = BodyConfig::Nastran {
        path: path.clone(),
        points,
        include_root: None,
    };
    let (a, b) = (modes(&procedural), modes(&from_deck));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-7 * x, "{x} vs {y} Hz");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
