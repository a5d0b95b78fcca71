//! Parametric description of the phenomenological car body (serde, every field defaulted).
//!
//! Coordinates in the vehicle frame (ISO 8855: x forward, y left, z up, origin at the front-axle
//! centre on the ground), metres. The body is generated on a regular grid (`grid_dx` along x,
//! `grid_dy` along y, `grid_dz` along z, all anchored at the origin), so every position named here
//! must lie on that grid; the generator reports any that does not.
//!
//! The tuning parameters (`body_stiffness_scale`, trim masses, the steering column section and the
//! steering-wheel mass) are set so that the body without engine on its suspension has its first
//! global torsion at 43 Hz, the steering-wheel modes at 31.5 Hz (vertical) and ~32 Hz (lateral)
//! and a mass of 1000 kg (paper §5.2, Table 1).

use serde::{Deserialize, Serialize};

use crate::fe::error::FeError;
use crate::fe::mesh::{BeamSection, Material};

/// A beam cross-section given by its shape.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "shape", rename_all = "snake_case")]
pub enum SectionSpec {
    /// Thin-walled rectangular tube: width `b` (local y), height `h` (local z), wall `t` (m).
    Box {
        /// Outer width along the local y axis, m.
        b: f64,
        /// Outer height along the local z axis, m.
        h: f64,
        /// Wall thickness, m (less than half of `b` and `h`).
        t: f64,
    },
    /// Thin-walled circular tube: outer diameter `d`, wall `t` (m).
    Tube {
        /// Outer diameter, m.
        d: f64,
        /// Wall thickness, m (at most half of `d`).
        t: f64,
    },
    /// Explicit section properties.
    Explicit {
        /// Cross-section area, m².
        area: f64,
        /// Second moment of area about the local y axis, m⁴.
        iy: f64,
        /// Second moment of area about the local z axis, m⁴.
        iz: f64,
        /// Saint-Venant torsion constant, m⁴.
        j: f64,
    },
}

impl SectionSpec {
    /// Section properties; `what` names the section in errors.
    pub fn section(&self, what: &str) -> Result<BeamSection, FeError> {
        let bad = |m: String| Err(FeError::InvalidInput(format!("section {what}: {m}")));
        let s = match *self {
            SectionSpec::Box { b, h, t } => {
                if !(b > 0.0 && h > 0.0 && t > 0.0 && 2.0 * t < b.min(h)) {
                    return bad(format!("box needs b, h > 2 t > 0, got b={b}, h={h}, t={t}"));
                }
                BeamSection::box_tube(b, h, t)
            }
            SectionSpec::Tube { d, t } => {
                if !(d > 0.0 && t > 0.0 && 2.0 * t <= d) {
                    return bad(format!("tube needs d >= 2 t > 0, got d={d}, t={t}"));
                }
                BeamSection::circular_tube(d, t)
            }
            SectionSpec::Explicit { area, iy, iz, j } => {
                BeamSection::rigid_in_shear(area, iy, iz, j)
            }
        };
        if [s.area, s.iy, s.iz, s.j]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0)
        {
            Ok(s)
        } else {
            bad(format!("non-positive or non-finite properties {s:?}"))
        }
    }
}

/// Main dimensions of the body.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Geometry {
    /// Wheelbase (m): the rear axle is at x = −wheelbase.
    pub wheelbase: f64,
    /// Half width of floor, sills, roof (m).
    pub half_width: f64,
    /// Floor and sill height (m).
    pub floor_z: f64,
    /// Firewall (front plate) position (m).
    pub firewall_x: f64,
    /// Rear end of floor and rear panel (m).
    pub rear_x: f64,
    /// Front end of the girders, front cross panel (m).
    pub front_x: f64,
    /// Cowl rear edge / cross-car beam position (m).
    pub cowl_x: f64,
    /// Top of firewall and cowl height (m).
    pub cowl_z: f64,
    /// Roof height (m).
    pub roof_z: f64,
    /// Front edge of the roof (windscreen header) (m).
    pub roof_front_x: f64,
    /// Rear edge of the roof (rear header) (m).
    pub roof_rear_x: f64,
    /// B-pillar position (m).
    pub b_pillar_x: f64,
    /// Front edge of the rear quarter panels (m).
    pub quarter_front_x: f64,
    /// Front edge of the parcel shelf (m).
    pub shelf_x: f64,
    /// Height of parcel shelf and top of rear and quarter panels (m).
    pub shelf_z: f64,
    /// Lower end of the C-pillar on the quarter panel top edge (m).
    pub c_pillar_foot_x: f64,
    /// Lateral position of the front girders (engine rails) and floor rails, ± (m).
    pub girder_y: f64,
    /// Height of the front girders (m).
    pub girder_z: f64,
    /// Height of the top of the wheel-house aprons above the girders (m).
    pub apron_top_z: f64,
    /// Floor cross-member positions (m).
    pub cross_member_x: Vec<f64>,
    /// Roof header and bow positions (m).
    pub roof_bow_x: Vec<f64>,
    /// Grid spacing along x (m).
    pub grid_dx: f64,
    /// Grid spacing along y (m).
    pub grid_dy: f64,
    /// Grid spacing along z (m).
    pub grid_dz: f64,
}

impl Default for Geometry {
    fn default() -> Self {
        Self {
            wheelbase: 2.54,
            half_width: 0.70,
            floor_z: 0.25,
            firewall_x: -0.50,
            rear_x: -3.30,
            front_x: 0.70,
            cowl_x: -0.80,
            cowl_z: 0.95,
            roof_z: 1.35,
            roof_front_x: -1.00,
            roof_rear_x: -2.60,
            b_pillar_x: -1.60,
            quarter_front_x: -2.30,
            shelf_x: -2.50,
            shelf_z: 0.85,
            c_pillar_foot_x: -3.00,
            girder_y: 0.40,
            girder_z: 0.55,
            apron_top_z: 0.85,
            cross_member_x: vec![-0.80, -1.60, -2.50],
            roof_bow_x: vec![-1.00, -1.60, -2.10, -2.60],
            grid_dx: 0.10,
            grid_dy: 0.05,
            grid_dz: 0.10,
        }
    }
}

/// Sheet thicknesses of the panels (m).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Thicknesses {
    /// Floor.
    pub floor: f64,
    /// Roof.
    pub roof: f64,
    /// Firewall / front plate (supports the steering column).
    pub firewall: f64,
    /// Cowl (plenum) between firewall and cross-car beam.
    pub cowl: f64,
    /// Rear panel.
    pub rear_panel: f64,
    /// Rear quarter panels.
    pub quarter: f64,
    /// Parcel shelf.
    pub shelf: f64,
    /// Wheel-house aprons above the girders.
    pub apron: f64,
    /// Front cross panel (radiator support) between the girders.
    pub front_panel: f64,
    /// Windscreen and rear window (bonded glass; carries much of the body's torsion stiffness).
    pub glass: f64,
    /// Effective bending thickness / sheet thickness of every panel: car-body panels are beaded
    /// and stiffened, which a coarse flat shell represents by a larger bending thickness.
    pub panel_bending_factor: f64,
}

impl Default for Thicknesses {
    fn default() -> Self {
        Self {
            floor: 0.0010,
            roof: 0.0008,
            firewall: 0.0010,
            cowl: 0.0010,
            rear_panel: 0.0010,
            quarter: 0.0009,
            shelf: 0.0008,
            apron: 0.0015,
            front_panel: 0.0010,
            glass: 0.0045,
            panel_bending_factor: 4.0,
        }
    }
}

/// Beam sections of the body frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Sections {
    /// Side sills along the floor edges.
    pub sill: SectionSpec,
    /// Longitudinal floor rails under the floor (continuation of the girders).
    pub floor_rail: SectionSpec,
    /// Central tunnel.
    pub tunnel: SectionSpec,
    /// Floor cross members.
    pub cross_member: SectionSpec,
    /// Front girders (engine rails), carrying the engine-mount nodes.
    pub girder: SectionSpec,
    /// Apron upper rails.
    pub upper_rail: SectionSpec,
    /// Front cross members (radiator support, top and bottom).
    pub front_cross: SectionSpec,
    /// Cross-car beam behind the cowl (carries the steering-column support).
    pub cross_car_beam: SectionSpec,
    /// Centre brace from the cross-car beam down to the tunnel (instrument-panel support).
    pub dash_brace: SectionSpec,
    /// Hinge pillars (lower A-pillars, firewall side edges).
    pub hinge_pillar: SectionSpec,
    /// A-pillars (cowl to roof).
    pub a_pillar: SectionSpec,
    /// B-pillars.
    pub b_pillar: SectionSpec,
    /// C-pillars.
    pub c_pillar: SectionSpec,
    /// Roof side rails.
    pub roof_rail: SectionSpec,
    /// Roof headers and bows.
    pub roof_bow: SectionSpec,
    /// Parcel-shelf front beam.
    pub shelf_beam: SectionSpec,
    /// Girder extensions down the firewall to the floor rails.
    pub girder_extension: SectionSpec,
    /// Fender braces from the strut towers (apron top at the front axle) to the hinge pillars.
    pub fender_brace: SectionSpec,
    /// Stiff links from the wheel centres to the body (suspension attachments).
    pub wheel_link: SectionSpec,
    /// Optional transverse stiffening bar between the front girders (paper §7.1).
    pub stiffening_bar: SectionSpec,
}

impl Default for Sections {
    fn default() -> Self {
        let b = |b, h, t| SectionSpec::Box { b, h, t };
        Self {
            sill: b(0.12, 0.15, 0.0020),
            floor_rail: b(0.06, 0.08, 0.0015),
            tunnel: b(0.12, 0.10, 0.0010),
            cross_member: b(0.05, 0.08, 0.0015),
            girder: b(0.09, 0.14, 0.0025),
            upper_rail: b(0.05, 0.06, 0.0015),
            front_cross: b(0.05, 0.08, 0.0015),
            cross_car_beam: SectionSpec::Tube {
                d: 0.050,
                t: 0.0020,
            },
            dash_brace: b(0.05, 0.05, 0.0020),
            hinge_pillar: b(0.10, 0.12, 0.0020),
            a_pillar: b(0.06, 0.08, 0.0015),
            b_pillar: b(0.08, 0.14, 0.0015),
            c_pillar: b(0.06, 0.10, 0.0015),
            roof_rail: b(0.06, 0.08, 0.0015),
            roof_bow: b(0.04, 0.05, 0.0010),
            shelf_beam: b(0.05, 0.06, 0.0012),
            girder_extension: b(0.07, 0.10, 0.0020),
            fender_brace: b(0.06, 0.08, 0.0020),
            wheel_link: b(0.08, 0.08, 0.0050),
            stiffening_bar: SectionSpec::Tube {
                d: 0.040,
                t: 0.0025,
            },
        }
    }
}

/// Steering column and wheel (tuned to the steering-wheel modes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Steering {
    /// Lower column end on the firewall (m).
    pub column_base: [f64; 3],
    /// Column support point, linked vertically to the cross-car beam (m).
    pub column_support: [f64; 3],
    /// Steering-wheel centre (m).
    pub wheel: [f64; 3],
    /// Column section (local y horizontal-lateral, local z in the vertical plane of the column).
    pub column_section: SectionSpec,
    /// Section of the link from the column support to the cross-car beam.
    pub bracket_section: SectionSpec,
    /// Beam elements between base and support, and between support and wheel.
    pub elements_per_segment: usize,
    /// Steering-wheel mass (kg) (wheel, airbag, hub).
    pub wheel_mass: f64,
    /// Steering-wheel inertia about its diameter and about its column axis (kg m²).
    pub wheel_inertia: [f64; 2],
}

impl Default for Steering {
    fn default() -> Self {
        Self {
            column_base: [-0.50, 0.35, 0.65],
            column_support: [-0.80, 0.35, 0.80],
            wheel: [-1.10, 0.35, 0.95],
            // Tuned by `examples/fe_tune.rs`.
            column_section: SectionSpec::Explicit {
                area: 2.5e-4,
                iy: 1.630e-8,
                iz: 2.268e-8,
                j: 8.0e-8,
            },
            bracket_section: SectionSpec::Box {
                b: 0.05,
                h: 0.05,
                t: 0.002,
            },
            elements_per_segment: 4,
            wheel_mass: 6.0,
            wheel_inertia: [0.04, 0.08],
        }
    }
}

/// Non-structural (trim) masses (kg), spread per length over the frame beams of each group (trim
/// hangs on the frame; on the thin panels it would only create spurious local panel modes).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Trim {
    /// Seats, carpets, fuel tank: on sills, floor rails, tunnel and floor cross members.
    pub floor: f64,
    /// Headliner, glass share: on roof rails and bows.
    pub roof: f64,
    /// Instrument panel, HVAC: on the cross-car beam.
    pub dash: f64,
    /// Radiator, bumper, lamps: on girders, upper rails and front cross members.
    pub front_end: f64,
    /// Rear bumper, spare wheel, boot trim: on the rear cross member.
    pub rear: f64,
    /// Doors and side glass: on hinge pillars and B-pillars.
    pub doors: f64,
}

impl Default for Trim {
    fn default() -> Self {
        Self {
            floor: 393.7,
            roof: 25.0,
            dash: 45.0,
            front_end: 50.0,
            rear: 70.0,
            doors: 100.0,
        }
    }
}

/// Suspension spring-dampers from the wheel centres to ground.
///
/// Vertically the wheel rate and the tyre act in series: 20 N/mm with 200 N/mm gives 18.2 N/mm per
/// corner, so the 1000 kg body bounces at 1.24 Hz (pitch 1.65 Hz, roll 1.49 Hz). Longitudinal and
/// lateral springs (100 N/mm per corner) are soft restraints standing for tyre and bushing
/// compliance, so the body has no free rigid-body modes (3.1–4.3 Hz, far below the 25 Hz of the
/// first elastic mode). The dampers (1 N s/mm per corner) give about 23 % of critical damping in
/// bounce. The springs act at the wheel-centre nodes, which are tied to the body by stiff links.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Suspension {
    /// Front wheel centre (left side; the right one is mirrored) (m).
    pub front_wheel_centre: [f64; 3],
    /// Lateral position and height of the rear wheel centre; x is −wheelbase (m).
    pub rear_wheel_centre_yz: [f64; 2],
    /// Suspension wheel rate (N/m).
    pub wheel_rate: f64,
    /// Tyre vertical rate (N/m).
    pub tyre_rate: f64,
    /// Longitudinal restraint per corner (N/m).
    pub longitudinal_rate: f64,
    /// Lateral restraint per corner (N/m).
    pub lateral_rate: f64,
    /// Vertical damper per corner (N s/m).
    pub vertical_damping: f64,
    /// Longitudinal and lateral damping per corner (N s/m).
    pub horizontal_damping: f64,
}

impl Default for Suspension {
    fn default() -> Self {
        Self {
            front_wheel_centre: [0.0, 0.72, 0.30],
            rear_wheel_centre_yz: [0.72, 0.30],
            wheel_rate: 20.0e3,
            tyre_rate: 200.0e3,
            longitudinal_rate: 100.0e3,
            lateral_rate: 100.0e3,
            vertical_damping: 1.0e3,
            horizontal_damping: 1.0e3,
        }
    }
}

/// Engine-mount positions on the front girders.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Mounts {
    /// x of the front and rear mount pairs (m); y = ±girder_y, z = girder_z.
    pub front_x: f64,
    /// x of the rear mount pair (m).
    pub rear_x: f64,
    /// The mount removed in the paper's improved three-mount vehicle.
    pub removed_in_three_mount_layout: MountPosition,
}

/// Where an engine mount sits on the front girders.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MountPosition {
    /// Front pair, left girder.
    FrontLeft,
    /// Front pair, right girder.
    FrontRight,
    /// Rear pair, left girder.
    RearLeft,
    /// Rear pair, right girder.
    RearRight,
}

impl MountPosition {
    /// The position's name, as in the configuration and the mesh's node names (`mount_<name>`).
    pub fn name(self) -> &'static str {
        match self {
            MountPosition::FrontLeft => "front_left",
            MountPosition::FrontRight => "front_right",
            MountPosition::RearLeft => "rear_left",
            MountPosition::RearRight => "rear_right",
        }
    }
}

impl Default for Mounts {
    fn default() -> Self {
        Self {
            front_x: 0.50,
            rear_x: -0.10,
            removed_in_three_mount_layout: MountPosition::RearRight,
        }
    }
}

/// Structural options of paper §7.1.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Options {
    /// Add a transverse stiffening bar between the front girders.
    pub stiffening_bar: bool,
    /// x position of the stiffening bar (m).
    pub stiffening_bar_x: f64,
    /// Stiffer front plate (firewall and cowl) supporting the steering column.
    pub stiff_front_plate: bool,
    /// Thickness factor of the stiffer front plate.
    pub front_plate_factor: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            stiffening_bar: false,
            stiffening_bar_x: 0.20,
            stiff_front_plate: false,
            front_plate_factor: 2.0,
        }
    }
}

/// The whole parametric body description.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ChassisConfig {
    /// Structural material of the body.
    pub material: Material,
    /// Glass of windscreen and rear window.
    pub glass: Material,
    /// Phenomenological stiffness factor on Young's modulus of the body structure and glass (not
    /// the steering column): the global tuning knob for the torsion frequency.
    pub body_stiffness_scale: f64,
    /// Main dimensions.
    pub geometry: Geometry,
    /// Panel thicknesses.
    pub thickness: Thicknesses,
    /// Frame sections.
    pub sections: Sections,
    /// Steering column and wheel.
    pub steering: Steering,
    /// Trim masses.
    pub trim: Trim,
    /// Suspension.
    pub suspension: Suspension,
    /// Engine mounts.
    pub mounts: Mounts,
    /// Driver's seat-rail node position (m).
    pub seat_rail: [f64; 3],
    /// Structural options.
    pub options: Options,
}

impl Default for ChassisConfig {
    fn default() -> Self {
        Self {
            material: Material::STEEL,
            glass: Material {
                youngs_modulus: 70.0e9,
                poisson_ratio: 0.22,
                density: 2500.0,
            },
            // Tuned by `examples/fe_tune.rs` (with trim.floor and the steering column section).
            body_stiffness_scale: 0.9464,
            geometry: Geometry::default(),
            thickness: Thicknesses::default(),
            sections: Sections::default(),
            steering: Steering::default(),
            trim: Trim::default(),
            suspension: Suspension::default(),
            mounts: Mounts::default(),
            seat_rail: [-1.40, 0.35, 0.25],
            options: Options::default(),
        }
    }
}

impl ChassisConfig {
    /// Parses a JSON description; missing fields take their defaults, unknown fields are errors.
    pub fn from_json(text: &str) -> Result<Self, FeError> {
        serde_json::from_str(text).map_err(|e| FeError::InvalidInput(format!("chassis JSON: {e}")))
    }

    /// Reads and parses a JSON description file.
    pub fn from_file(path: &std::path::Path) -> Result<Self, FeError> {
        let text = crate::text_file::read_limited(path, crate::text_file::CONFIG_LIMIT)
            .map_err(FeError::Io)?;
        Self::from_json(&text)
    }

    /// Pretty JSON of this description.
    pub fn to_json(&self) -> Result<String, FeError> {
        serde_json::to_string_pretty(self)
            .map_err(|e| FeError::InvalidInput(format!("chassis JSON: {e}")))
    }
}

impl ChassisConfig {
    /// Checks what serde cannot: sizes positive, positions on the grid and in order, the mount
    /// name known. [`crate::chassis::Chassis::build`] calls it first, so an error names the
    /// field rather than a degenerate element.
    pub fn validate(&self) -> Result<(), FeError> {
        let g = &self.geometry;
        let positive = [
            ("geometry.grid_dx", g.grid_dx),
            ("geometry.grid_dy", g.grid_dy),
            ("geometry.grid_dz", g.grid_dz),
            ("geometry.half_width", g.half_width),
            ("geometry.wheelbase", g.wheelbase),
            ("body_stiffness_scale", self.body_stiffness_scale),
            (
                "options.front_plate_factor",
                self.options.front_plate_factor,
            ),
            ("steering.wheel_mass", self.steering.wheel_mass),
            ("suspension.wheel_rate", self.suspension.wheel_rate),
            ("suspension.tyre_rate", self.suspension.tyre_rate),
        ];
        for (name, v) in positive {
            crate::fe::error::require_positive(name, v)?;
        }
        g.validate_grid(&[
            ("mounts.front_x", self.mounts.front_x),
            ("mounts.rear_x", self.mounts.rear_x),
        ])?;
        g.validate_order()?;
        g.validate_stations()
    }
}

fn on_grid(name: &str, v: f64, step: f64) -> Result<(), FeError> {
    let r = v / step;
    if v.is_finite() && (r - r.round()).abs() < 1e-6 {
        Ok(())
    } else {
        Err(FeError::InvalidInput(format!(
            "{name} = {v} is not a multiple of the grid spacing {step}"
        )))
    }
}

impl Geometry {
    /// The named positions, and the `more_x` positions along x, lie on the grid.
    fn validate_grid(&self, more_x: &[(&str, f64)]) -> Result<(), FeError> {
        let along_x = [
            ("geometry.firewall_x", self.firewall_x),
            ("geometry.rear_x", self.rear_x),
            ("geometry.front_x", self.front_x),
            ("geometry.cowl_x", self.cowl_x),
            ("geometry.roof_front_x", self.roof_front_x),
            ("geometry.roof_rear_x", self.roof_rear_x),
            ("geometry.b_pillar_x", self.b_pillar_x),
            ("geometry.quarter_front_x", self.quarter_front_x),
            ("geometry.shelf_x", self.shelf_x),
        ];
        for &(name, v) in along_x.iter().chain(more_x) {
            on_grid(name, v, self.grid_dx)?;
        }
        for (name, v) in [
            ("geometry.half_width", self.half_width),
            ("geometry.girder_y", self.girder_y),
        ] {
            on_grid(name, v, self.grid_dy)?;
        }
        // Heights are measured on the grid from the floor.
        for (name, v) in [
            ("geometry.cowl_z", self.cowl_z),
            ("geometry.shelf_z", self.shelf_z),
            ("geometry.girder_z", self.girder_z),
            ("geometry.apron_top_z", self.apron_top_z),
        ] {
            on_grid(name, v - self.floor_z, self.grid_dz)?;
        }
        Ok(())
    }

    /// The parts follow each other in the order the body is built from.
    fn validate_order(&self) -> Result<(), FeError> {
        let g = self;
        let ordered = [
            ("rear_x < quarter_front_x", g.rear_x < g.quarter_front_x),
            ("rear_x < shelf_x", g.rear_x < g.shelf_x),
            ("roof_rear_x < roof_front_x", g.roof_rear_x < g.roof_front_x),
            (
                "cowl_x < firewall_x < front_x",
                g.cowl_x < g.firewall_x && g.firewall_x < g.front_x,
            ),
            (
                "floor_z < girder_z < apron_top_z",
                g.floor_z < g.girder_z && g.girder_z < g.apron_top_z,
            ),
            (
                "apron_top_z <= cowl_z < roof_z",
                g.apron_top_z <= g.cowl_z && g.cowl_z < g.roof_z,
            ),
            (
                "0 < girder_y < half_width",
                0.0 < g.girder_y && g.girder_y < g.half_width,
            ),
        ];
        match ordered.iter().find(|(_, ok)| !ok) {
            Some((what, _)) => Err(FeError::InvalidInput(format!(
                "geometry must satisfy {what}"
            ))),
            None => Ok(()),
        }
    }

    /// Cross members and roof bows lie on the grid within their panels.
    fn validate_stations(&self) -> Result<(), FeError> {
        for (name, list, lo, hi) in [
            (
                "geometry.cross_member_x",
                &self.cross_member_x,
                self.rear_x,
                self.firewall_x,
            ),
            (
                "geometry.roof_bow_x",
                &self.roof_bow_x,
                self.roof_rear_x,
                self.roof_front_x,
            ),
        ] {
            for &x in list.iter() {
                on_grid(name, x, self.grid_dx)?;
                if !(lo..=hi).contains(&x) {
                    return Err(FeError::InvalidInput(format!(
                        "{name} entry {x} lies outside its panel ({lo} ..= {hi})"
                    )));
                }
            }
        }
        Ok(())
    }
}
