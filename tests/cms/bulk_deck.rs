//! A user's body from a bulk data deck runs through the same reduction and coupled model as the
//! procedural one: the procedural chassis written as a deck and named by GRID ids gives the same
//! coupled engine-in-body modes (paper Table 1, middle column) as the procedural chassis itself.

use std::collections::BTreeMap;
use std::path::Path;

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::Chassis;
use engine_mount_chassis::cms::CacheSetting;
use engine_mount_chassis::model::scene::{build, BodyOptions, SceneKind};
use engine_mount_chassis::model::{BodyConfig, VehicleConfig};
use engine_mount_chassis::nastran::write_bulk_deck;

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

/// The default vehicle with its procedural chassis written as a bulk data deck
/// (`dir/chassis.bdf`, the writer's text passed through `edit`), the points its mounts and
/// outputs use named by GRID id (node index + 1).
pub(crate) fn default_vehicle_as_deck(
    dir: &Path,
    edit: impl FnOnce(String) -> String,
) -> VehicleConfig {
    let chassis = Chassis::build(&ChassisConfig::default()).expect("chassis");
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join("chassis.bdf");
    std::fs::write(&path, edit(write_bulk_deck(&chassis.mesh).expect("deck"))).unwrap();
    let mut vehicle = VehicleConfig::default();
    let mut names: Vec<String> = vehicle
        .mounts
        .iter()
        .filter_map(|m| m.body_node.clone())
        .collect();
    names.extend(vehicle.outputs.iter().cloned());
    let points: BTreeMap<String, u32> = names
        .iter()
        .map(|n| (n.clone(), chassis.node(n).expect("named node") as u32 + 1))
        .collect();
    vehicle.body = BodyConfig::Nastran {
        path,
        points,
        include_root: None,
        damping: None,
    };
    vehicle
}

#[test]
fn the_procedural_chassis_as_a_bulk_deck_gives_the_same_coupled_modes() {
    let procedural = VehicleConfig::default();
    let dir = std::env::temp_dir().join(format!("emc-deck-{}", std::process::id()));
    let from_deck = default_vehicle_as_deck(&dir, |deck| deck);
    let (a, b) = (modes(&procedural), modes(&from_deck));
    assert_eq!(a.len(), b.len());
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-7 * x, "{x} vs {y} Hz");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
