//! The procedural body without engine on its suspension against the paper's targets (paper §5.2,
//! Table 1): 1000 kg, first global torsion 43 Hz, steering wheel 31.5 Hz vertical / ~32 Hz
//! lateral; structural options of paper §7.1 move the frequencies in the right direction.

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::modal::{
    describe, steering_wheel_pair, ModeDescription, ModeKind,
};
use engine_mount_chassis::chassis::{
    Chassis, MountLayout, SEAT_RAIL, STEERING_WHEEL, WHEEL_CENTRES,
};
use engine_mount_chassis::eigen::{lowest_modes, Modes};
use engine_mount_chassis::fe::assembly::{assemble, translational_mass, Assembled};
use engine_mount_chassis::fe::checks::{check_assembled, check_mesh, CheckLimits};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

struct Analysis {
    chassis: Chassis,
    asm: Assembled,
    raw: Modes,
    modes: Vec<ModeDescription>,
}

fn analyse(config: &ChassisConfig) -> Analysis {
    let chassis = Chassis::build(config).unwrap();
    let asm = assemble(&chassis.mesh).unwrap();
    let raw = lowest_modes(&asm.k, &asm.m, 30, -1.0).unwrap();
    let modes = describe(&chassis.mesh, &asm, &raw).unwrap();
    Analysis {
        chassis,
        asm,
        raw,
        modes,
    }
}

/// Static stiffness against spreading the front mount pair apart laterally [N/m].
fn front_mount_spread_stiffness(an: &Analysis) -> f64 {
    let n = an.asm.dofs.n_free();
    let left = an.chassis.node("mount_front_left").unwrap();
    let right = an.chassis.node("mount_front_right").unwrap();
    let (gl, gr) = (
        an.asm.dofs.global(left, 1).unwrap(),
        an.asm.dofs.global(right, 1).unwrap(),
    );
    let mut f = Mat::<f64>::zeros(n, 1);
    f[(gl, 0)] = 1.0;
    f[(gr, 0)] = -1.0;
    let llt = an.asm.k.sp_cholesky(Side::Lower).unwrap();
    llt.solve_in_place(f.as_mut());
    1.0 / (f[(gl, 0)] - f[(gr, 0)])
}

fn within(value: f64, target: f64, tolerance: f64) -> bool {
    (value / target - 1.0).abs() <= tolerance
}

/// The two steering-wheel modes: (more vertical, more lateral).
fn wheel_pair(modes: &[ModeDescription]) -> (&ModeDescription, &ModeDescription) {
    let (v, l) = steering_wheel_pair(modes).expect("steering-wheel modes");
    (&modes[v], &modes[l])
}

/// The front-end mode with the most lateral girder/apron motion.
fn front_lateral(an: &Analysis) -> f64 {
    let front = &an.chassis.mesh.regions["front_end"];
    let mut best = (0.0, 0.0);
    for d in &an.modes {
        if d.energy["front_end"] < 0.3 || d.kind != ModeKind::FrontEnd {
            continue;
        }
        let mut lateral = 0.0;
        let mut total = 0.0;
        for &n in front {
            for dof in 0..3 {
                if let Some(g) = an.asm.dofs.global(n, dof) {
                    let v = an.raw.shapes[(g, d.index)].powi(2);
                    total += v;
                    if dof == 1 {
                        lateral += v;
                    }
                }
            }
        }
        if lateral / total > best.0 {
            best = (lateral / total, d.frequency_hz);
        }
    }
    best.1
}

#[test]
fn body_without_engine_meets_the_paper_targets() {
    let an = analyse(&ChassisConfig::default());
    let mesh = &an.chassis.mesh;
    check_mesh(mesh, &CheckLimits::default()).unwrap();
    check_assembled(&an.asm).unwrap();

    // Size of the paper's model: ~2600 nodes, 2200 shells, 600 beams, 15000 DOF.
    let n_dof = an.asm.dofs.n_free();
    println!(
        "nodes {}, shells {}, beams {}, dofs {n_dof}",
        mesh.nodes.len(),
        mesh.shells.len(),
        mesh.beams.len()
    );
    assert!((2300..=2900).contains(&mesh.nodes.len()));
    assert!((2000..=2600).contains(&mesh.shells.len()));
    assert!((540..=700).contains(&mesh.beams.len()));
    assert!((13500..=16500).contains(&n_dof));

    for dir in 0..3 {
        let mass = translational_mass(&an.asm, dir);
        println!("mass seen by a rigid translation along axis {dir}: {mass:.1} kg");
        assert!(within(mass, 1000.0, 0.05), "mass {mass}");
    }

    for d in &an.modes {
        println!("{}", d.summary());
    }
    // The six lowest modes are the rigid body on its suspension (≤ 5 Hz).
    for d in &an.modes[..6] {
        assert!(
            matches!(d.kind, ModeKind::RigidBody(_)) && d.frequency_hz < 5.0,
            "{}",
            d.summary()
        );
    }
    let bending = an.modes.iter().find(|d| d.kind == ModeKind::GlobalBending);
    let bending = bending.expect("a global vertical bending mode below 100 Hz");
    println!("first global bending: {:.2} Hz", bending.frequency_hz);
    let torsion = an
        .modes
        .iter()
        .find(|d| d.kind == ModeKind::GlobalTorsion)
        .expect("torsion mode");
    assert!(
        within(torsion.frequency_hz, 43.0, 0.05),
        "torsion {}",
        torsion.summary()
    );
    let (vertical, lateral) = wheel_pair(&an.modes);
    println!(
        "steering wheel: vertical {:.2} Hz, lateral {:.2} Hz",
        vertical.frequency_hz, lateral.frequency_hz
    );
    assert!(
        within(vertical.frequency_hz, 31.5, 0.05),
        "{}",
        vertical.summary()
    );
    assert!(
        within(lateral.frequency_hz, 32.07, 0.05),
        "{}",
        lateral.summary()
    );
    assert!(vertical.energy["steering"] > 0.4 && lateral.energy["steering"] > 0.4);
    assert_eq!(vertical.kind, ModeKind::SteeringWheelVertical);
    assert!(
        vertical.frequency_hz < lateral.frequency_hz,
        "paper order: vertical below lateral"
    );
}

#[test]
fn special_nodes_sit_where_the_engine_model_expects_them() {
    let chassis = Chassis::build(&ChassisConfig::default()).unwrap();
    let at = |name: &str| chassis.mesh.nodes[chassis.node(name).unwrap()];
    let expect = [
        ("mount_front_left", [0.50, 0.40, 0.55]),
        ("mount_front_right", [0.50, -0.40, 0.55]),
        ("mount_rear_left", [-0.10, 0.40, 0.55]),
        ("mount_rear_right", [-0.10, -0.40, 0.55]),
    ];
    for (name, p) in expect {
        let q = at(name);
        for d in 0..3 {
            assert!((q[d] - p[d]).abs() < 1e-12, "{name}: {q:?} vs {p:?}");
        }
    }
    let four = chassis.mount_nodes(MountLayout::Four).unwrap();
    let three = chassis.mount_nodes(MountLayout::Three).unwrap();
    assert_eq!(four.len(), 4);
    assert_eq!(three.len(), 3);
    assert!(three.iter().all(|m| four.contains(m)));
    for name in WHEEL_CENTRES {
        let x = at(name).x;
        assert!(
            (x - 0.0).abs() < 1e-12 || (x + 2.54).abs() < 1e-12,
            "{name} at x = {x}"
        );
    }
    at(STEERING_WHEEL);
    at(SEAT_RAIL);
}

#[test]
fn stiffening_bar_raises_the_front_end_and_a_stiffer_front_plate_the_steering_wheel() {
    let base_cfg = ChassisConfig::default();
    let base = analyse(&base_cfg);
    let base_front = front_lateral(&base);
    let mut bar_cfg = base_cfg.clone();
    bar_cfg.options.stiffening_bar = true;
    let bar = analyse(&bar_cfg);
    let bar_front = front_lateral(&bar);
    let (base_spread, bar_spread) = (
        front_mount_spread_stiffness(&base),
        front_mount_spread_stiffness(&bar),
    );
    println!(
        "static stiffness against spreading the front mounts: {:.0} N/mm -> {:.0} N/mm ({:+.0} %)",
        base_spread / 1e3,
        bar_spread / 1e3,
        100.0 * (bar_spread / base_spread - 1.0)
    );
    assert!(bar_spread > base_spread);
    println!(
        "front-end lateral mode: {base_front:.2} Hz -> {bar_front:.2} Hz with the stiffening bar \
         ({:+.1} %)",
        100.0 * (bar_front / base_front - 1.0)
    );
    assert!(bar_front > base_front * 1.005);

    let mut plate_cfg = base_cfg.clone();
    plate_cfg.options.stiff_front_plate = true;
    let plate = analyse(&plate_cfg);
    let (bv, bl) = wheel_pair(&base.modes);
    let (pv, pl) = wheel_pair(&plate.modes);
    println!(
        "steering wheel: {:.2} / {:.2} Hz -> {:.2} / {:.2} Hz with the stiffer front plate",
        bv.frequency_hz, bl.frequency_hz, pv.frequency_hz, pl.frequency_hz
    );
    assert!(pv.frequency_hz > bv.frequency_hz && pl.frequency_hz > bl.frequency_hz);
}

#[test]
fn description_errors_name_the_field() {
    let err = ChassisConfig::from_json(r#"{"geometry": {"grid_dx": -1.0}}"#)
        .and_then(|c| Chassis::build(&c).map(|_| ()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("geometry.grid_dx"), "{err}");
    let err = ChassisConfig::from_json(r#"{"mounts": {"front_x": 0.55}}"#)
        .and_then(|c| Chassis::build(&c).map(|_| ()))
        .unwrap_err()
        .to_string();
    assert!(err.contains("mounts.front_x"), "{err}");
    let err = ChassisConfig::from_json(r#"{"no_such_field": 1}"#)
        .unwrap_err()
        .to_string();
    assert!(err.contains("no_such_field"), "{err}");
}

#[test]
fn shipped_improved_description_is_the_default_with_the_paper_7_1_options() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/configs/chassis_improved.json");
    let improved = ChassisConfig::from_file(std::path::Path::new(path)).unwrap();
    let mut expected = ChassisConfig::default();
    expected.options.stiffening_bar = true;
    expected.options.stiff_front_plate = true;
    assert_eq!(improved, expected);
    let chassis = Chassis::build(&improved).unwrap();
    assert_eq!(chassis.mount_nodes(MountLayout::Three).unwrap().len(), 3);
}

#[test]
fn shipped_json_description_is_the_default() {
    let text =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/configs/chassis.json"))
            .unwrap();
    assert_eq!(
        ChassisConfig::from_json(&text).unwrap(),
        ChassisConfig::default()
    );
}

/// One of today's bodies, recorded from commit abde0ff's hand-written `frame()` before the frame
/// became a table: a regression check of that refactor (the body must not move), not a check of
/// the physics, which the tests above do against the paper.
struct TodaysBody {
    nodes: usize,
    shells: usize,
    beams: usize,
    /// Mass seen by a rigid translation along x, y, z (kg).
    mass: [f64; 3],
    /// The 30 lowest natural frequencies on the suspension (Hz).
    frequencies: [f64; 30],
    /// Region names and their node counts.
    regions: [(&'static str, usize); 21],
}

fn assert_reproduces(config: &ChassisConfig, today: &TodaysBody) {
    let chassis = Chassis::build(config).unwrap();
    let mesh = &chassis.mesh;
    assert_eq!(
        (mesh.nodes.len(), mesh.shells.len(), mesh.beams.len()),
        (today.nodes, today.shells, today.beams),
        "nodes, shells, beams"
    );
    let regions: Vec<(&str, usize)> = mesh
        .regions
        .iter()
        .map(|(name, ids)| (name.as_str(), ids.len()))
        .collect();
    assert_eq!(regions, today.regions);
    let close = |got: f64, want: f64| (got / want - 1.0).abs() <= 1e-9;
    let asm = assemble(mesh).unwrap();
    for (d, &want) in today.mass.iter().enumerate() {
        let got = translational_mass(&asm, d);
        assert!(
            close(got, want),
            "mass along axis {d}: {got} kg, today {want} kg"
        );
    }
    let modes = lowest_modes(&asm.k, &asm.m, 30, -1.0).unwrap();
    for (i, (&got, &want)) in modes
        .frequencies_hz()
        .iter()
        .zip(&today.frequencies)
        .enumerate()
    {
        assert!(close(got, want), "mode {i}: {got} Hz, today {want} Hz");
    }
}

const REGIONS_TODAY: [(&str, usize); 21] = [
    ("body", 2537),
    ("column_bracket", 2),
    ("column_lower", 5),
    ("cowl", 123),
    ("cross_member", 87),
    ("firewall", 244),
    ("floor", 841),
    ("floor_rail", 58),
    ("front_end", 176),
    ("glass", 319),
    ("pillar", 62),
    ("quarter", 154),
    ("rear_cross_member", 29),
    ("rear_panel", 203),
    ("roof", 493),
    ("roof_rail", 34),
    ("shelf", 261),
    ("sill", 58),
    ("steering", 5),
    ("suspension", 8),
    ("tunnel", 29),
];

#[test]
fn the_default_body_is_todays_body() {
    assert_reproduces(
        &ChassisConfig::default(),
        &TodaysBody {
            nodes: 2549,
            shells: 2396,
            beams: 636,
            mass: [1000.0447653194659; 3],
            frequencies: [
                1.2361461891334637,
                1.4890138730794302,
                1.6519939812197812,
                3.100244315673804,
                3.229348481364915,
                4.270910367050018,
                26.471470547613237,
                31.32346396972967,
                32.39111014849134,
                38.07021792144857,
                44.50684828056241,
                46.96961714653364,
                48.56486873463693,
                53.05212993782183,
                59.09517332453419,
                60.342098987376254,
                63.06207665249143,
                72.17308052895702,
                72.46229889911449,
                75.50267585380544,
                75.81735373431303,
                76.59672356845404,
                79.14043954659388,
                85.07771593325033,
                88.39838125808082,
                90.43659795853041,
                91.1049202657218,
                103.08134913399981,
                103.65021904454788,
                105.24037312017835,
            ],
            regions: REGIONS_TODAY,
        },
    );
}

#[test]
fn the_body_with_the_paper_7_1_options_is_todays_body() {
    let mut improved = ChassisConfig::default();
    improved.options.stiffening_bar = true;
    improved.options.stiff_front_plate = true;
    // The stiffening bar adds 15 nodes and 16 beams to the front end.
    let mut regions = REGIONS_TODAY;
    regions[0].1 += 15;
    regions[8].1 += 15;
    assert_reproduces(
        &improved,
        &TodaysBody {
            nodes: 2564,
            shells: 2396,
            beams: 652,
            mass: [1012.8843779942484; 3],
            frequencies: [
                1.2346986407656118,
                1.4807354135745912,
                1.6305723200282936,
                3.0970726571629936,
                3.2107711447427625,
                4.230115623049478,
                26.72162229222526,
                31.669660744867087,
                32.66852131654992,
                39.23504036947578,
                45.30969770912645,
                46.97305505344074,
                49.45232270574175,
                53.527922623410916,
                59.150285491474236,
                60.36993585022727,
                64.66213998032046,
                72.53086139723146,
                73.42340763410371,
                75.53809950545858,
                76.31795736076147,
                79.0599414341953,
                79.99412060851436,
                85.69932743232674,
                88.9236603035322,
                90.45261719697261,
                92.90922461765433,
                103.49256084317513,
                103.96359620165585,
                105.51424892069299,
            ],
            regions,
        },
    );
}
