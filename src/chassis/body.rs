//! Procedural generator of the phenomenological car body from a [`ChassisConfig`].
//!
//! Shell panels: floor, roof, firewall (front plate), cowl, rear panel, rear quarter panels,
//! parcel shelf, wheel-house aprons, front cross panel. Beams: sills, floor rails, tunnel, floor
//! cross members, front girders (engine rails, carrying the engine-mount nodes), girder extensions,
//! apron upper rails, front cross members, cross-car beam, hinge/A/B/C pillars, roof rails and
//! bows, parcel-shelf beam, steering column, wheel links, optional stiffening bar. Point mass: the
//! steering wheel. Ground springs: suspension at the four wheel centres.
//!
//! All parts are generated on one grid and nodes are merged by position, so panels and beams that
//! share an edge share its nodes.

use std::collections::{BTreeMap, HashMap};

use nalgebra::{Matrix3, Vector3};

use super::config::{ChassisConfig, Geometry, SectionSpec, Sections, Thicknesses, Trim};
use crate::fe::checks::{check_mesh, CheckLimits};
use crate::fe::error::FeError;
use crate::fe::mesh::{Beam, BeamSection, GroundSpring, Material, Mesh, PointMass, Shell};

/// Engine-mount layout: the original four mounts or the paper's improved three-mount vehicle.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MountLayout {
    /// Front-left, front-right, rear-left, rear-right.
    Four,
    /// The four minus `mounts.removed_in_three_mount_layout`.
    Three,
}

/// Names of the four engine-mount positions (suffix of the `mount_` named nodes).
pub const MOUNT_NAMES: [&str; 4] = ["front_left", "front_right", "rear_left", "rear_right"];

/// Names of the wheel-centre nodes.
pub const WHEEL_CENTRES: [&str; 4] = [
    "wheel_front_left",
    "wheel_front_right",
    "wheel_rear_left",
    "wheel_rear_right",
];

/// Named node of the steering-wheel centre.
pub const STEERING_WHEEL: &str = "steering_wheel";
/// Named node of the driver's seat rail.
pub const SEAT_RAIL: &str = "seat_rail";

/// Region names of the generated mesh (node sets), which the mode descriptions ([`super::modal`])
/// measure kinetic-energy fractions over.
pub mod region {
    /// Steering column (above its support) and wheel.
    pub const STEERING: &str = "steering";
    /// Front end ahead of the firewall: girders, aprons, front panel.
    pub const FRONT_END: &str = "front_end";
    /// Firewall / front plate.
    pub const FIREWALL: &str = "firewall";
    /// Rear panel (rear cross-section of the body).
    pub const REAR_PANEL: &str = "rear_panel";
    /// Floor panel.
    pub const FLOOR: &str = "floor";
    /// Roof panel and roof bows.
    pub const ROOF: &str = "roof";
    /// The whole body structure except the steering column.
    pub const BODY: &str = "body";
    /// Cowl panel, cross-car beam and dash brace.
    pub const COWL: &str = "cowl";
    /// Rear quarter panels.
    pub const QUARTER: &str = "quarter";
    /// Parcel shelf and its front beam.
    pub const SHELF: &str = "shelf";
    /// Windscreen and rear window.
    pub const GLASS: &str = "glass";
    /// Side sills.
    pub const SILL: &str = "sill";
    /// Floor rails.
    pub const FLOOR_RAIL: &str = "floor_rail";
    /// Central tunnel.
    pub const TUNNEL: &str = "tunnel";
    /// Floor cross members.
    pub const CROSS_MEMBER: &str = "cross_member";
    /// Rear cross member.
    pub const REAR_CROSS_MEMBER: &str = "rear_cross_member";
    /// Hinge, A, B and C pillars.
    pub const PILLAR: &str = "pillar";
    /// Roof side rails.
    pub const ROOF_RAIL: &str = "roof_rail";
    /// Steering column below its support.
    pub const COLUMN_LOWER: &str = "column_lower";
    /// Link from the column support up to the cross-car beam.
    pub const COLUMN_BRACKET: &str = "column_bracket";
    /// Wheel links and wheel centres.
    pub const SUSPENSION: &str = "suspension";
}

/// The generated body.
#[derive(Debug, Clone)]
pub struct Chassis {
    /// The mesh, with named nodes and regions.
    pub mesh: Mesh,
    /// The description it was built from.
    pub config: ChassisConfig,
}

impl Chassis {
    /// Generates the body described by `config`.
    pub fn build(config: &ChassisConfig) -> Result<Self, FeError> {
        let mesh = Builder::new(config)?.build()?;
        // A description that yields a degenerate or disconnected mesh is rejected here, with the
        // element or node named, rather than surfacing later as a singular factorisation.
        check_mesh(&mesh, &CheckLimits::default())?;
        Ok(Self {
            mesh,
            config: config.clone(),
        })
    }

    /// Node id of a named node; error if absent.
    pub fn node(&self, name: &str) -> Result<usize, FeError> {
        self.mesh
            .named(name)
            .ok_or_else(|| FeError::InvalidInput(format!("no named node '{name}' in the chassis")))
    }

    /// Engine-mount nodes `(name, node id)` of a layout.
    pub fn mount_nodes(&self, layout: MountLayout) -> Result<Vec<(String, usize)>, FeError> {
        let removed = self.config.mounts.removed_in_three_mount_layout.name();
        MOUNT_NAMES
            .iter()
            .filter(|n| layout == MountLayout::Four || **n != removed)
            .map(|n| Ok((format!("mount_{n}"), self.node(&format!("mount_{n}"))?)))
            .collect()
    }
}

/// An x position of the body, named by the [`Geometry`] field it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum X {
    Front,
    /// The front axle, x = 0.
    Axle,
    Firewall,
    Cowl,
    RoofFront,
    BPillar,
    QuarterFront,
    Shelf,
    RoofRear,
    CPillarFoot,
    Rear,
    /// The station of a run laid at listed positions ([`Lay`]).
    Station,
}

/// A lateral position, on the left (+y) for the rows that are mirrored to the right.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Y {
    Centre,
    /// Body side, +half_width.
    Left,
    /// Body side, −half_width.
    Right,
    /// Girder and floor-rail line, +girder_y.
    LeftRail,
    /// Girder and floor-rail line, −girder_y.
    RightRail,
}

/// A height, named by the [`Geometry`] field it is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Z {
    Floor,
    Girder,
    ApronTop,
    Shelf,
    Cowl,
    Roof,
}

/// A point of the body, by coordinates named in the geometry.
#[derive(Debug, Clone, Copy)]
struct At(X, Y, Z);

impl At {
    /// The position; `side` (±1) mirrors y, `station` is the x of [`X::Station`].
    fn resolve(self, g: &Geometry, side: f64, station: f64) -> Vector3<f64> {
        let x = match self.0 {
            X::Front => g.front_x,
            X::Axle => 0.0,
            X::Firewall => g.firewall_x,
            X::Cowl => g.cowl_x,
            X::RoofFront => g.roof_front_x,
            X::BPillar => g.b_pillar_x,
            X::QuarterFront => g.quarter_front_x,
            X::Shelf => g.shelf_x,
            X::RoofRear => g.roof_rear_x,
            X::CPillarFoot => g.c_pillar_foot_x,
            X::Rear => g.rear_x,
            X::Station => station,
        };
        let y = match self.1 {
            Y::Centre => 0.0,
            Y::Left => g.half_width,
            Y::Right => -g.half_width,
            Y::LeftRail => g.girder_y,
            Y::RightRail => -g.girder_y,
        };
        let z = match self.2 {
            Z::Floor => g.floor_z,
            Z::Girder => g.girder_z,
            Z::ApronTop => g.apron_top_z,
            Z::Shelf => g.shelf_z,
            Z::Cowl => g.cowl_z,
            Z::Roof => g.roof_z,
        };
        Vector3::new(x, side * y, z)
    }
}

/// Which trim mass ([`Trim`]) a beam run carries; each group's mass is spread uniformly over the
/// length of its runs as laid out.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum TrimGroup {
    Floor,
    Roof,
    Dash,
    FrontEnd,
    Rear,
    Doors,
}

impl TrimGroup {
    const ALL: [TrimGroup; 6] = [
        TrimGroup::Floor,
        TrimGroup::Roof,
        TrimGroup::Dash,
        TrimGroup::FrontEnd,
        TrimGroup::Rear,
        TrimGroup::Doors,
    ];

    /// The configuration field and its mass (kg).
    fn mass(self, t: &Trim) -> (&'static str, f64) {
        match self {
            TrimGroup::Floor => ("trim.floor", t.floor),
            TrimGroup::Roof => ("trim.roof", t.roof),
            TrimGroup::Dash => ("trim.dash", t.dash),
            TrimGroup::FrontEnd => ("trim.front_end", t.front_end),
            TrimGroup::Rear => ("trim.rear", t.rear),
            TrimGroup::Doors => ("trim.doors", t.doors),
        }
    }
}

/// How often a row of [`FRAME`] is laid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lay {
    /// Once as written.
    Once,
    /// On the right, then mirrored on the left.
    EachSide,
    /// At every `geometry.cross_member_x`.
    CrossMembers,
    /// At every `geometry.roof_bow_x`.
    RoofBows,
    /// At `options.stiffening_bar_x` if `options.stiffening_bar`; its left end must already be a
    /// node of the girder.
    StiffeningBar,
}

impl Lay {
    fn stations(self, cfg: &ChassisConfig) -> Vec<f64> {
        match self {
            Lay::Once | Lay::EachSide => vec![0.0],
            Lay::CrossMembers => cfg.geometry.cross_member_x.clone(),
            Lay::RoofBows => cfg.geometry.roof_bow_x.clone(),
            Lay::StiffeningBar if cfg.options.stiffening_bar => vec![cfg.options.stiffening_bar_x],
            Lay::StiffeningBar => Vec::new(),
        }
    }
}

/// The [`Sections`] field of a run: its name (for errors) and how to read it.
type SectionOf = (&'static str, fn(&Sections) -> &SectionSpec);

/// A straight beam run of the body frame.
struct Run {
    lay: Lay,
    region: &'static str,
    section: SectionOf,
    from: At,
    to: At,
    trim: Option<TrimGroup>,
}

/// The body frame. Mirrored rows come first and are laid as a block, right side then left side,
/// which keeps the node and element numbering of the hand-written frame this table replaced.
#[rustfmt::skip]
static FRAME: [Run; 23] = [
    Run { lay: Lay::EachSide, region: region::SILL, section: ("sill", |s| &s.sill),
          from: At(X::Rear, Y::Left, Z::Floor), to: At(X::Firewall, Y::Left, Z::Floor), trim: Some(TrimGroup::Floor) },
    Run { lay: Lay::EachSide, region: region::FLOOR_RAIL, section: ("floor_rail", |s| &s.floor_rail),
          from: At(X::Rear, Y::LeftRail, Z::Floor), to: At(X::Firewall, Y::LeftRail, Z::Floor), trim: Some(TrimGroup::Floor) },
    Run { lay: Lay::EachSide, region: region::FRONT_END, section: ("girder", |s| &s.girder),
          from: At(X::Firewall, Y::LeftRail, Z::Girder), to: At(X::Front, Y::LeftRail, Z::Girder), trim: Some(TrimGroup::FrontEnd) },
    Run { lay: Lay::EachSide, region: region::FIREWALL, section: ("girder_extension", |s| &s.girder_extension),
          from: At(X::Firewall, Y::LeftRail, Z::Floor), to: At(X::Firewall, Y::LeftRail, Z::Girder), trim: None },
    Run { lay: Lay::EachSide, region: region::FRONT_END, section: ("upper_rail", |s| &s.upper_rail),
          from: At(X::Firewall, Y::LeftRail, Z::ApronTop), to: At(X::Front, Y::LeftRail, Z::ApronTop), trim: Some(TrimGroup::FrontEnd) },
    // Load paths from the front end into the body: kick-down of the girder to the floor rail and
    // continuation of the upper rail to the cross-car beam.
    Run { lay: Lay::EachSide, region: region::FIREWALL, section: ("girder_extension", |s| &s.girder_extension),
          from: At(X::Firewall, Y::LeftRail, Z::Girder), to: At(X::Cowl, Y::LeftRail, Z::Floor), trim: None },
    Run { lay: Lay::EachSide, region: region::FIREWALL, section: ("upper_rail", |s| &s.upper_rail),
          from: At(X::Firewall, Y::LeftRail, Z::ApronTop), to: At(X::Cowl, Y::LeftRail, Z::Cowl), trim: None },
    Run { lay: Lay::EachSide, region: region::FRONT_END, section: ("fender_brace", |s| &s.fender_brace),
          from: At(X::Axle, Y::LeftRail, Z::ApronTop), to: At(X::Firewall, Y::Left, Z::ApronTop), trim: None },
    Run { lay: Lay::EachSide, region: region::PILLAR, section: ("hinge_pillar", |s| &s.hinge_pillar),
          from: At(X::Firewall, Y::Left, Z::Floor), to: At(X::Firewall, Y::Left, Z::Cowl), trim: Some(TrimGroup::Doors) },
    Run { lay: Lay::EachSide, region: region::PILLAR, section: ("a_pillar", |s| &s.a_pillar),
          from: At(X::Cowl, Y::Left, Z::Cowl), to: At(X::RoofFront, Y::Left, Z::Roof), trim: None },
    Run { lay: Lay::EachSide, region: region::PILLAR, section: ("b_pillar", |s| &s.b_pillar),
          from: At(X::BPillar, Y::Left, Z::Floor), to: At(X::BPillar, Y::Left, Z::Roof), trim: Some(TrimGroup::Doors) },
    Run { lay: Lay::EachSide, region: region::PILLAR, section: ("c_pillar", |s| &s.c_pillar),
          from: At(X::RoofRear, Y::Left, Z::Roof), to: At(X::CPillarFoot, Y::Left, Z::Shelf), trim: None },
    Run { lay: Lay::EachSide, region: region::ROOF_RAIL, section: ("roof_rail", |s| &s.roof_rail),
          from: At(X::RoofRear, Y::Left, Z::Roof), to: At(X::RoofFront, Y::Left, Z::Roof), trim: Some(TrimGroup::Roof) },
    Run { lay: Lay::Once, region: region::TUNNEL, section: ("tunnel", |s| &s.tunnel),
          from: At(X::Rear, Y::Centre, Z::Floor), to: At(X::Firewall, Y::Centre, Z::Floor), trim: Some(TrimGroup::Floor) },
    Run { lay: Lay::CrossMembers, region: region::CROSS_MEMBER, section: ("cross_member", |s| &s.cross_member),
          from: At(X::Station, Y::Right, Z::Floor), to: At(X::Station, Y::Left, Z::Floor), trim: Some(TrimGroup::Floor) },
    Run { lay: Lay::Once, region: region::REAR_CROSS_MEMBER, section: ("cross_member", |s| &s.cross_member),
          from: At(X::Rear, Y::Right, Z::Floor), to: At(X::Rear, Y::Left, Z::Floor), trim: Some(TrimGroup::Rear) },
    Run { lay: Lay::Once, region: region::FRONT_END, section: ("front_cross", |s| &s.front_cross),
          from: At(X::Front, Y::RightRail, Z::Girder), to: At(X::Front, Y::LeftRail, Z::Girder), trim: Some(TrimGroup::FrontEnd) },
    Run { lay: Lay::Once, region: region::FRONT_END, section: ("front_cross", |s| &s.front_cross),
          from: At(X::Front, Y::RightRail, Z::ApronTop), to: At(X::Front, Y::LeftRail, Z::ApronTop), trim: Some(TrimGroup::FrontEnd) },
    Run { lay: Lay::Once, region: region::COWL, section: ("cross_car_beam", |s| &s.cross_car_beam),
          from: At(X::Cowl, Y::Right, Z::Cowl), to: At(X::Cowl, Y::Left, Z::Cowl), trim: Some(TrimGroup::Dash) },
    Run { lay: Lay::Once, region: region::COWL, section: ("dash_brace", |s| &s.dash_brace),
          from: At(X::Cowl, Y::Centre, Z::Cowl), to: At(X::Cowl, Y::Centre, Z::Floor), trim: None },
    Run { lay: Lay::RoofBows, region: region::ROOF, section: ("roof_bow", |s| &s.roof_bow),
          from: At(X::Station, Y::Right, Z::Roof), to: At(X::Station, Y::Left, Z::Roof), trim: Some(TrimGroup::Roof) },
    Run { lay: Lay::Once, region: region::SHELF, section: ("shelf_beam", |s| &s.shelf_beam),
          from: At(X::Shelf, Y::Right, Z::Shelf), to: At(X::Shelf, Y::Left, Z::Shelf), trim: None },
    Run { lay: Lay::StiffeningBar, region: region::FRONT_END, section: ("stiffening_bar", |s| &s.stiffening_bar),
          from: At(X::Station, Y::RightRail, Z::Girder), to: At(X::Station, Y::LeftRail, Z::Girder), trim: None },
];

/// What a panel is made of.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Skin {
    /// Body steel, beaded (bending thickness × `thickness.panel_bending_factor`).
    Steel,
    /// Body steel of the front plate: thickness × `options.front_plate_factor` when
    /// `options.stiff_front_plate`.
    FrontPlate,
    /// Bonded glass, flat.
    Glass,
}

/// A flat panel: the parallelogram of `corner` and the far ends of its two edges, meshed on the
/// grid. Panels carry only their own mass: trim on the thin sheets would only create spurious
/// local panel modes.
struct Panel {
    region: &'static str,
    corner: At,
    u_end: At,
    v_end: At,
    thickness: fn(&Thicknesses) -> f64,
    skin: Skin,
    /// Laid on the right, then mirrored on the left.
    mirrored: bool,
}

/// The body panels: floor, roof, firewall, cowl, rear, quarters, shelf, glass, aprons, front.
#[rustfmt::skip]
static PANELS: [Panel; 11] = [
    Panel { region: region::FLOOR, thickness: |t| t.floor, skin: Skin::Steel, mirrored: false,
            corner: At(X::Rear, Y::Right, Z::Floor), u_end: At(X::Firewall, Y::Right, Z::Floor), v_end: At(X::Rear, Y::Left, Z::Floor) },
    Panel { region: region::ROOF, thickness: |t| t.roof, skin: Skin::Steel, mirrored: false,
            corner: At(X::RoofRear, Y::Right, Z::Roof), u_end: At(X::RoofFront, Y::Right, Z::Roof), v_end: At(X::RoofRear, Y::Left, Z::Roof) },
    Panel { region: region::FIREWALL, thickness: |t| t.firewall, skin: Skin::FrontPlate, mirrored: false,
            corner: At(X::Firewall, Y::Right, Z::Floor), u_end: At(X::Firewall, Y::Left, Z::Floor), v_end: At(X::Firewall, Y::Right, Z::Cowl) },
    Panel { region: region::COWL, thickness: |t| t.cowl, skin: Skin::FrontPlate, mirrored: false,
            corner: At(X::Cowl, Y::Right, Z::Cowl), u_end: At(X::Firewall, Y::Right, Z::Cowl), v_end: At(X::Cowl, Y::Left, Z::Cowl) },
    Panel { region: region::REAR_PANEL, thickness: |t| t.rear_panel, skin: Skin::Steel, mirrored: false,
            corner: At(X::Rear, Y::Right, Z::Floor), u_end: At(X::Rear, Y::Left, Z::Floor), v_end: At(X::Rear, Y::Right, Z::Shelf) },
    Panel { region: region::QUARTER, thickness: |t| t.quarter, skin: Skin::Steel, mirrored: true,
            corner: At(X::Rear, Y::Left, Z::Floor), u_end: At(X::QuarterFront, Y::Left, Z::Floor), v_end: At(X::Rear, Y::Left, Z::Shelf) },
    Panel { region: region::SHELF, thickness: |t| t.shelf, skin: Skin::Steel, mirrored: false,
            corner: At(X::Rear, Y::Right, Z::Shelf), u_end: At(X::Shelf, Y::Right, Z::Shelf), v_end: At(X::Rear, Y::Left, Z::Shelf) },
    // Windscreen between cowl and roof, rear window between roof and shelf.
    Panel { region: region::GLASS, thickness: |t| t.glass, skin: Skin::Glass, mirrored: false,
            corner: At(X::Cowl, Y::Right, Z::Cowl), u_end: At(X::Cowl, Y::Left, Z::Cowl), v_end: At(X::RoofFront, Y::Right, Z::Roof) },
    Panel { region: region::GLASS, thickness: |t| t.glass, skin: Skin::Glass, mirrored: false,
            corner: At(X::CPillarFoot, Y::Right, Z::Shelf), u_end: At(X::CPillarFoot, Y::Left, Z::Shelf), v_end: At(X::RoofRear, Y::Right, Z::Roof) },
    // Wheel-house aprons above the girders and the front cross panel between them.
    Panel { region: region::FRONT_END, thickness: |t| t.apron, skin: Skin::Steel, mirrored: true,
            corner: At(X::Firewall, Y::LeftRail, Z::Girder), u_end: At(X::Front, Y::LeftRail, Z::Girder), v_end: At(X::Firewall, Y::LeftRail, Z::ApronTop) },
    Panel { region: region::FRONT_END, thickness: |t| t.front_panel, skin: Skin::Steel, mirrored: false,
            corner: At(X::Front, Y::RightRail, Z::Girder), u_end: At(X::Front, Y::LeftRail, Z::Girder), v_end: At(X::Front, Y::RightRail, Z::ApronTop) },
];

/// A run of [`FRAME`] placed in the body.
struct Placed {
    run: &'static Run,
    from: Vector3<f64>,
    to: Vector3<f64>,
}

/// Every run of the frame in laying order.
fn place_frame(cfg: &ChassisConfig) -> Vec<Placed> {
    let g = &cfg.geometry;
    let mirrored = FRAME.iter().filter(|r| r.lay == Lay::EachSide);
    let sides = [-1.0, 1.0].into_iter();
    let pairs = sides.flat_map(|side| mirrored.clone().map(move |run| (run, side, 0.0)));
    let single = FRAME.iter().filter(|r| r.lay != Lay::EachSide);
    let stationed = single.flat_map(|run| {
        let stations = run.lay.stations(cfg);
        stations.into_iter().map(move |x| (run, 1.0, x))
    });
    pairs
        .chain(stationed)
        .map(|(run, side, x)| Placed {
            run,
            from: run.from.resolve(g, side, x),
            to: run.to.resolve(g, side, x),
        })
        .collect()
}

/// Trim mass per length (kg/m) of each [`TrimGroup`], from the lengths of its placed runs.
fn trim_per_length(trim: &Trim, frame: &[Placed]) -> Result<[f64; 6], FeError> {
    let mut length = [0.0; 6];
    for p in frame {
        if let Some(group) = p.run.trim {
            length[group as usize] += (p.to - p.from).norm();
        }
    }
    let mut per_length = [0.0; 6];
    for group in TrimGroup::ALL {
        let (name, mass) = group.mass(trim);
        let l = length[group as usize];
        per_length[group as usize] = if mass == 0.0 {
            0.0
        } else if l > 0.0 {
            mass / l
        } else {
            return Err(FeError::InvalidInput(format!(
                "{name} = {mass} kg has no beams of the frame to hang on"
            )));
        };
    }
    Ok(per_length)
}

fn key(p: &Vector3<f64>) -> [i64; 3] {
    // 0.1 mm: far below the grid spacing, far above round-off of the grid arithmetic.
    [
        (p.x * 1e4).round() as i64,
        (p.y * 1e4).round() as i64,
        (p.z * 1e4).round() as i64,
    ]
}

fn v3(p: [f64; 3]) -> Vector3<f64> {
    Vector3::new(p[0], p[1], p[2])
}

/// Material, section and trim of a beam line.
struct Member {
    material: Material,
    section: BeamSection,
    /// Non-structural mass per length (kg/m).
    extra_per_length: f64,
}

/// Material and thicknesses of a panel.
struct Sheet {
    material: Material,
    thickness: f64,
    bending_thickness: f64,
}

struct Builder<'a> {
    cfg: &'a ChassisConfig,
    body: Material,
    mesh: Mesh,
    lookup: HashMap<[i64; 3], usize>,
    regions: BTreeMap<String, Vec<usize>>,
}

impl<'a> Builder<'a> {
    fn new(cfg: &'a ChassisConfig) -> Result<Self, FeError> {
        cfg.validate()?;
        let mut body = cfg.material;
        body.youngs_modulus *= cfg.body_stiffness_scale;
        Ok(Self {
            cfg,
            body,
            mesh: Mesh::default(),
            lookup: HashMap::new(),
            regions: BTreeMap::new(),
        })
    }

    fn node(&mut self, p: Vector3<f64>, region: &str) -> usize {
        let id = match self.lookup.get(&key(&p)) {
            Some(&id) => id,
            None => {
                let id = self.mesh.add_node(p);
                self.lookup.insert(key(&p), id);
                id
            }
        };
        self.regions.entry(region.to_string()).or_default().push(id);
        id
    }

    fn existing(&self, p: Vector3<f64>, what: &str) -> Result<usize, FeError> {
        self.lookup.get(&key(&p)).copied().ok_or_else(|| {
            FeError::InvalidInput(format!(
                "{what} at ({:.4}, {:.4}, {:.4}) m is not a node of the body structure; put it on \
                 the grid of the part it attaches to",
                p.x, p.y, p.z
            ))
        })
    }

    fn divisions(&self, d: &Vector3<f64>) -> usize {
        let g = &self.cfg.geometry;
        let n = [
            d.x.abs() / g.grid_dx,
            d.y.abs() / g.grid_dy,
            d.z.abs() / g.grid_dz,
        ]
        .iter()
        .map(|v| v.round() as usize)
        .max()
        .unwrap_or(1);
        n.max(1)
    }

    /// Flat panel spanned by `u`, `v` from `corner`, meshed on the grid.
    fn panel(
        &mut self,
        region: &str,
        corner: Vector3<f64>,
        [u, v]: [Vector3<f64>; 2],
        sheet: &Sheet,
    ) {
        let (nu, nv) = (self.divisions(&u), self.divisions(&v));
        let mut ids = vec![vec![0; nv + 1]; nu + 1];
        for (i, row) in ids.iter_mut().enumerate() {
            for (j, id) in row.iter_mut().enumerate() {
                let p = corner + u * (i as f64 / nu as f64) + v * (j as f64 / nv as f64);
                *id = self.node(p, region);
            }
        }
        for i in 0..nu {
            for j in 0..nv {
                self.mesh.shells.push(Shell {
                    nodes: [ids[i][j], ids[i + 1][j], ids[i + 1][j + 1], ids[i][j + 1]],
                    material: sheet.material,
                    thickness: sheet.thickness,
                    bending_thickness: sheet.bending_thickness,
                    extra_mass_per_area: 0.0,
                    section: None,
                });
            }
        }
    }

    /// Straight beam line from `a` to `b` in `divisions` elements; returns its nodes.
    fn line(
        &mut self,
        region: &str,
        [a, b]: [Vector3<f64>; 2],
        member: &Member,
        divisions: usize,
    ) -> Vec<usize> {
        let d = b - a;
        let n = divisions.max(1);
        let dir = d.normalize();
        let orientation = if dir.z.abs() > 0.7 {
            Vector3::new(1.0, 0.0, 0.0)
        } else if dir.x.abs() >= dir.y.abs() {
            Vector3::new(0.0, 1.0, 0.0)
        } else {
            Vector3::new(1.0, 0.0, 0.0)
        };
        let ids: Vec<usize> = (0..=n)
            .map(|i| self.node(a + d * (i as f64 / n as f64), region))
            .collect();
        for w in ids.windows(2) {
            self.mesh.beams.push(Beam {
                nodes: [w[0], w[1]],
                material: member.material,
                section: member.section,
                orientation,
                extra_mass_per_length: member.extra_per_length,
            });
        }
        ids
    }

    fn build(mut self) -> Result<Mesh, FeError> {
        self.panels();
        self.frame()?;
        let body_nodes: Vec<usize> = (0..self.mesh.nodes.len()).collect();
        self.regions.insert(region::BODY.into(), body_nodes);

        self.steering()?;
        self.suspension()?;
        self.named_points()?;

        let mut mesh = self.mesh;
        for (name, mut ids) in self.regions {
            ids.sort_unstable();
            ids.dedup();
            mesh.regions.insert(name, ids);
        }
        Ok(mesh)
    }

    /// Lays [`PANELS`].
    fn panels(&mut self) {
        let cfg = self.cfg;
        let mut glass = cfg.glass;
        glass.youngs_modulus *= cfg.body_stiffness_scale;
        for panel in &PANELS {
            let base = (panel.thickness)(&cfg.thickness);
            let (material, thickness, bending_factor) = match panel.skin {
                Skin::Steel => (self.body, base, cfg.thickness.panel_bending_factor),
                Skin::FrontPlate if cfg.options.stiff_front_plate => (
                    self.body,
                    base * cfg.options.front_plate_factor,
                    cfg.thickness.panel_bending_factor,
                ),
                Skin::FrontPlate => (self.body, base, cfg.thickness.panel_bending_factor),
                Skin::Glass => (glass, base, 1.0),
            };
            let sheet = Sheet {
                material,
                thickness,
                bending_thickness: thickness * bending_factor,
            };
            let sides: &[f64] = if panel.mirrored { &[-1.0, 1.0] } else { &[1.0] };
            for &side in sides {
                let at = |p: At| p.resolve(&cfg.geometry, side, 0.0);
                let corner = at(panel.corner);
                let edges = [at(panel.u_end) - corner, at(panel.v_end) - corner];
                self.panel(panel.region, corner, edges, &sheet);
            }
        }
    }

    /// Lays [`FRAME`] with the trim spread over its runs.
    fn frame(&mut self) -> Result<(), FeError> {
        let frame = place_frame(self.cfg);
        let per_length = trim_per_length(&self.cfg.trim, &frame)?;
        for p in &frame {
            if p.run.lay == Lay::StiffeningBar {
                self.existing(p.to, "stiffening bar end (options.stiffening_bar_x)")?;
            }
            let (name, spec) = p.run.section;
            let member = Member {
                material: self.body,
                section: spec(&self.cfg.sections).section(name)?,
                extra_per_length: p.run.trim.map_or(0.0, |t| per_length[t as usize]),
            };
            let n = self.divisions(&(p.to - p.from));
            self.line(p.run.region, [p.from, p.to], &member, n);
        }
        Ok(())
    }

    fn steering(&mut self) -> Result<(), FeError> {
        let st = &self.cfg.steering;
        let g = &self.cfg.geometry;
        let base = v3(st.column_base);
        let support = v3(st.column_support);
        let wheel = v3(st.wheel);
        self.existing(base, "steering.column_base")?;
        let above = Vector3::new(support.x, support.y, g.cowl_z);
        self.existing(above, "cross-car beam node above steering.column_support")?;
        let n = st.elements_per_segment.max(1);
        // The column is not scaled with the body: it has its own tuning (section, wheel mass).
        let column = Member {
            material: self.cfg.material,
            section: st.column_section.section("steering.column_section")?,
            extra_per_length: 0.0,
        };
        let bracket = Member {
            material: self.body,
            section: st.bracket_section.section("steering.bracket_section")?,
            extra_per_length: 0.0,
        };
        self.line(region::COLUMN_LOWER, [base, support], &column, n);
        self.line(region::STEERING, [support, wheel], &column, n);
        self.line(region::COLUMN_BRACKET, [support, above], &bracket, 1);
        let wheel_node = self.node(wheel, region::STEERING);
        let axis = (wheel - support).normalize();
        let [i_d, i_a] = st.wheel_inertia;
        let inertia = Matrix3::identity() * i_d + axis * axis.transpose() * (i_a - i_d);
        self.mesh.masses.push(PointMass {
            node: wheel_node,
            mass: st.wheel_mass,
            inertia,
        });
        self.mesh
            .named_nodes
            .insert(STEERING_WHEEL.into(), wheel_node);
        let support_node = self.existing(support, "steering.column_support")?;
        self.mesh
            .named_nodes
            .insert("column_support".into(), support_node);
        Ok(())
    }

    fn suspension(&mut self) -> Result<(), FeError> {
        let su = &self.cfg.suspension;
        let g = &self.cfg.geometry;
        let series = 1.0 / (1.0 / su.wheel_rate + 1.0 / su.tyre_rate);
        let stiffness = [su.longitudinal_rate, su.lateral_rate, series, 0.0, 0.0, 0.0];
        let damping = [
            su.horizontal_damping,
            su.horizontal_damping,
            su.vertical_damping,
            0.0,
            0.0,
            0.0,
        ];
        let rear_x = -g.wheelbase;
        let rear_attach_x = (rear_x / g.grid_dx).round() * g.grid_dx;
        let corners = [
            (WHEEL_CENTRES[0], 1.0, true),
            (WHEEL_CENTRES[1], -1.0, true),
            (WHEEL_CENTRES[2], 1.0, false),
            (WHEEL_CENTRES[3], -1.0, false),
        ];
        let link = Member {
            material: self.body,
            section: self.cfg.sections.wheel_link.section("wheel_link")?,
            extra_per_length: 0.0,
        };
        for (name, side, front) in corners {
            let (centre, attach) = if front {
                let c = su.front_wheel_centre;
                (
                    Vector3::new(c[0], side * c[1], c[2]),
                    Vector3::new(c[0], side * g.girder_y, g.girder_z),
                )
            } else {
                let [cy, cz] = su.rear_wheel_centre_yz;
                (
                    Vector3::new(rear_x, side * cy, cz),
                    Vector3::new(rear_attach_x, side * g.half_width, g.floor_z),
                )
            };
            self.existing(attach, &format!("suspension attachment of {name}"))?;
            let ids = self.line(region::SUSPENSION, [attach, centre], &link, 1);
            let node = ids[1];
            self.mesh.named_nodes.insert(name.into(), node);
            self.mesh.ground_springs.push(GroundSpring {
                node,
                stiffness,
                damping,
            });
        }
        Ok(())
    }

    fn named_points(&mut self) -> Result<(), FeError> {
        let g = &self.cfg.geometry;
        let m = &self.cfg.mounts;
        let positions = [
            (m.front_x, 1.0),
            (m.front_x, -1.0),
            (m.rear_x, 1.0),
            (m.rear_x, -1.0),
        ];
        for (name, (x, side)) in MOUNT_NAMES.iter().zip(positions) {
            let id = self.existing(
                Vector3::new(x, side * g.girder_y, g.girder_z),
                &format!("engine mount {name} (mounts.front_x / mounts.rear_x on the girder)"),
            )?;
            self.mesh.named_nodes.insert(format!("mount_{name}"), id);
        }
        let seat = self.existing(v3(self.cfg.seat_rail), "seat_rail")?;
        self.mesh.named_nodes.insert(SEAT_RAIL.into(), seat);
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stations_are_used_exactly_by_the_rows_laid_at_stations() {
        for run in &FRAME {
            let stationed = matches!(
                run.lay,
                Lay::CrossMembers | Lay::RoofBows | Lay::StiffeningBar
            );
            for end in [run.from, run.to] {
                assert_eq!(
                    end.0 == X::Station,
                    stationed,
                    "{} ({:?})",
                    run.section.0,
                    run.lay
                );
            }
        }
        for panel in &PANELS {
            for p in [panel.corner, panel.u_end, panel.v_end] {
                assert_ne!(p.0, X::Station, "panel of {}", panel.region);
            }
        }
    }

    #[test]
    fn trim_hangs_on_the_laid_length_of_its_group() {
        let mut cfg = ChassisConfig::default();
        cfg.geometry.cross_member_x.push(-2.0);
        let g = &cfg.geometry;
        let frame = place_frame(&cfg);
        let per_length = trim_per_length(&cfg.trim, &frame).unwrap();
        // Sills, floor rails and tunnel along the floor, and the four cross members across it.
        let floor = 5.0 * (g.firewall_x - g.rear_x) + 4.0 * 2.0 * g.half_width;
        let want = cfg.trim.floor / floor;
        let got = per_length[TrimGroup::Floor as usize];
        assert!((got / want - 1.0).abs() < 1e-14, "{got} vs {want}");
        let mut laid = 0.0;
        for p in &frame {
            if let Some(t) = p.run.trim {
                laid += per_length[t as usize] * (p.to - p.from).norm();
            }
        }
        let t = &cfg.trim;
        let total = t.floor + t.roof + t.dash + t.front_end + t.rear + t.doors;
        assert!((laid / total - 1.0).abs() < 1e-14, "{laid} vs {total}");
    }
}
