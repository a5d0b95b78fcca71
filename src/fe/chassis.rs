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

use super::chassis_config::{ChassisConfig, SectionSpec};
use super::checks::{check_mesh, CheckLimits};
use super::error::FeError;
use super::mesh::{Beam, GroundSpring, Material, Mesh, PointMass, Shell};

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

/// Region names used for mode descriptions.
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
    /// Roof panel.
    pub const ROOF: &str = "roof";
    /// The whole body structure except the steering column.
    pub const BODY: &str = "body";
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
        let removed = &self.config.mounts.removed_in_three_mount_layout;
        MOUNT_NAMES
            .iter()
            .filter(|n| layout == MountLayout::Four || **n != removed.as_str())
            .map(|n| Ok((format!("mount_{n}"), self.node(&format!("mount_{n}"))?)))
            .collect()
    }
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

struct Builder<'a> {
    cfg: &'a ChassisConfig,
    body: Material,
    mesh: Mesh,
    lookup: HashMap<[i64; 3], usize>,
    regions: BTreeMap<String, Vec<usize>>,
}

impl<'a> Builder<'a> {
    fn new(cfg: &'a ChassisConfig) -> Result<Self, FeError> {
        validate(cfg)?;
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

    /// Flat body-steel panel spanned by the edge vectors `u`, `v` from `corner`, on the grid.
    fn panel(
        &mut self,
        region: &str,
        corner: Vector3<f64>,
        u: Vector3<f64>,
        v: Vector3<f64>,
        thickness: f64,
        bending_factor: f64,
    ) {
        self.panel_of(region, corner, u, v, self.body, thickness, bending_factor);
    }

    /// Flat panel of `material` spanned by `u`, `v` from `corner`, meshed on the grid.
    #[allow(clippy::too_many_arguments)]
    fn panel_of(
        &mut self,
        region: &str,
        corner: Vector3<f64>,
        u: Vector3<f64>,
        v: Vector3<f64>,
        material: Material,
        thickness: f64,
        bending_factor: f64,
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
                    material,
                    thickness,
                    bending_thickness: thickness * bending_factor,
                    extra_mass_per_area: 0.0,
                });
            }
        }
    }

    /// Straight beam line from `a` to `b` on the grid; returns its nodes.
    #[allow(clippy::too_many_arguments)]
    fn line(
        &mut self,
        region: &str,
        a: Vector3<f64>,
        b: Vector3<f64>,
        section: &SectionSpec,
        what: &str,
        material: Material,
        extra_per_length: f64,
        divisions: Option<usize>,
    ) -> Result<Vec<usize>, FeError> {
        let d = b - a;
        let n = divisions.unwrap_or_else(|| self.divisions(&d)).max(1);
        let section = section.section(what)?;
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
                material,
                section,
                orientation,
                extra_mass_per_length: extra_per_length,
            });
        }
        Ok(ids)
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

    /// Shell panels: floor, roof, firewall, cowl, rear, quarters, shelf, glass, aprons, front.
    fn panels(&mut self) {
        let cfg = self.cfg;
        let g = &cfg.geometry;
        let t = &cfg.thickness;
        let w = g.half_width;
        let ex = Vector3::new(1.0, 0.0, 0.0);
        let ey = Vector3::new(0.0, 1.0, 0.0);
        let ez = Vector3::new(0.0, 0.0, 1.0);
        let p = Vector3::new;
        let front_plate = if cfg.options.stiff_front_plate {
            cfg.options.front_plate_factor
        } else {
            1.0
        };

        // Panels carry only their own mass; their bending thickness represents beads.
        let bend = t.panel_bending_factor;
        self.panel(
            region::FLOOR,
            p(g.rear_x, -w, g.floor_z),
            ex * (g.firewall_x - g.rear_x),
            ey * 2.0 * w,
            t.floor,
            bend,
        );
        self.panel(
            region::ROOF,
            p(g.roof_rear_x, -w, g.roof_z),
            ex * (g.roof_front_x - g.roof_rear_x),
            ey * 2.0 * w,
            t.roof,
            bend,
        );
        self.panel(
            region::FIREWALL,
            p(g.firewall_x, -w, g.floor_z),
            ey * 2.0 * w,
            ez * (g.cowl_z - g.floor_z),
            t.firewall * front_plate,
            bend,
        );
        self.panel(
            "cowl",
            p(g.cowl_x, -w, g.cowl_z),
            ex * (g.firewall_x - g.cowl_x),
            ey * 2.0 * w,
            t.cowl * front_plate,
            bend,
        );
        let rear_h = g.shelf_z - g.floor_z;
        self.panel(
            region::REAR_PANEL,
            p(g.rear_x, -w, g.floor_z),
            ey * 2.0 * w,
            ez * rear_h,
            t.rear_panel,
            bend,
        );
        for side in [-1.0, 1.0] {
            self.panel(
                "quarter",
                p(g.rear_x, side * w, g.floor_z),
                ex * (g.quarter_front_x - g.rear_x),
                ez * rear_h,
                t.quarter,
                bend,
            );
        }
        self.panel(
            "shelf",
            p(g.rear_x, -w, g.shelf_z),
            ex * (g.shelf_x - g.rear_x),
            ey * 2.0 * w,
            t.shelf,
            bend,
        );
        // Bonded glass: windscreen between cowl and roof, rear window between roof and shelf.
        let mut glass = cfg.glass;
        glass.youngs_modulus *= cfg.body_stiffness_scale;
        let windscreen = p(g.roof_front_x - g.cowl_x, 0.0, g.roof_z - g.cowl_z);
        self.panel_of(
            "glass",
            p(g.cowl_x, -w, g.cowl_z),
            ey * 2.0 * w,
            windscreen,
            glass,
            t.glass,
            1.0,
        );
        let rear_window = p(g.roof_rear_x - g.c_pillar_foot_x, 0.0, g.roof_z - g.shelf_z);
        self.panel_of(
            "glass",
            p(g.c_pillar_foot_x, -w, g.shelf_z),
            ey * 2.0 * w,
            rear_window,
            glass,
            t.glass,
            1.0,
        );
        let apron_l = g.front_x - g.firewall_x;
        let apron_h = g.apron_top_z - g.girder_z;
        for side in [-1.0, 1.0] {
            self.panel(
                region::FRONT_END,
                p(g.firewall_x, side * g.girder_y, g.girder_z),
                ex * apron_l,
                ez * apron_h,
                t.apron,
                bend,
            );
        }
        self.panel(
            region::FRONT_END,
            p(g.front_x, -g.girder_y, g.girder_z),
            ey * 2.0 * g.girder_y,
            ez * apron_h,
            t.front_panel,
            bend,
        );
    }

    /// Beams of the body frame, with the trim spread over them, and the optional stiffening bar.
    fn frame(&mut self) -> Result<(), FeError> {
        let cfg = self.cfg;
        let g = &cfg.geometry;
        let s = &cfg.sections;
        let trim = &cfg.trim;
        let w = g.half_width;
        let body = self.body;
        let p = Vector3::new;

        // Trim per length of each beam group.
        let floor_l = g.firewall_x - g.rear_x;
        let floor_trim = trim.floor / (5.0 * floor_l + 2.0 * w * g.cross_member_x.len() as f64);
        let roof_l = g.roof_front_x - g.roof_rear_x;
        let roof_trim = trim.roof / (2.0 * roof_l + 2.0 * w * g.roof_bow_x.len() as f64);
        let dash_trim = trim.dash / (2.0 * w);
        let apron_l = g.front_x - g.firewall_x;
        let front_trim = trim.front_end / (4.0 * apron_l + 4.0 * g.girder_y);
        let rear_trim = trim.rear / (2.0 * w);
        let door_trim = trim.doors / (2.0 * ((g.cowl_z - g.floor_z) + (g.roof_z - g.floor_z)));

        // Beams of the body frame.
        for side in [-1.0, 1.0] {
            let y = side * w;
            let gy = side * g.girder_y;
            self.line(
                "sill",
                p(g.rear_x, y, g.floor_z),
                p(g.firewall_x, y, g.floor_z),
                &s.sill,
                "sill",
                body,
                floor_trim,
                None,
            )?;
            self.line(
                "floor_rail",
                p(g.rear_x, gy, g.floor_z),
                p(g.firewall_x, gy, g.floor_z),
                &s.floor_rail,
                "floor_rail",
                body,
                floor_trim,
                None,
            )?;
            self.line(
                region::FRONT_END,
                p(g.firewall_x, gy, g.girder_z),
                p(g.front_x, gy, g.girder_z),
                &s.girder,
                "girder",
                body,
                front_trim,
                None,
            )?;
            self.line(
                region::FIREWALL,
                p(g.firewall_x, gy, g.floor_z),
                p(g.firewall_x, gy, g.girder_z),
                &s.girder_extension,
                "girder_extension",
                body,
                0.0,
                None,
            )?;
            self.line(
                region::FRONT_END,
                p(g.firewall_x, gy, g.apron_top_z),
                p(g.front_x, gy, g.apron_top_z),
                &s.upper_rail,
                "upper_rail",
                body,
                front_trim,
                None,
            )?;
            // Load paths from the front end into the body: kick-down of the girder to the floor
            // rail and continuation of the upper rail to the cross-car beam.
            self.line(
                region::FIREWALL,
                p(g.firewall_x, gy, g.girder_z),
                p(g.cowl_x, gy, g.floor_z),
                &s.girder_extension,
                "girder_extension",
                body,
                0.0,
                None,
            )?;
            self.line(
                region::FIREWALL,
                p(g.firewall_x, gy, g.apron_top_z),
                p(g.cowl_x, gy, g.cowl_z),
                &s.upper_rail,
                "upper_rail",
                body,
                0.0,
                None,
            )?;
            self.line(
                region::FRONT_END,
                p(0.0, gy, g.apron_top_z),
                p(g.firewall_x, y, g.apron_top_z),
                &s.fender_brace,
                "fender_brace",
                body,
                0.0,
                None,
            )?;
            self.line(
                "pillar",
                p(g.firewall_x, y, g.floor_z),
                p(g.firewall_x, y, g.cowl_z),
                &s.hinge_pillar,
                "hinge_pillar",
                body,
                door_trim,
                None,
            )?;
            self.line(
                "pillar",
                p(g.cowl_x, y, g.cowl_z),
                p(g.roof_front_x, y, g.roof_z),
                &s.a_pillar,
                "a_pillar",
                body,
                0.0,
                None,
            )?;
            self.line(
                "pillar",
                p(g.b_pillar_x, y, g.floor_z),
                p(g.b_pillar_x, y, g.roof_z),
                &s.b_pillar,
                "b_pillar",
                body,
                door_trim,
                None,
            )?;
            self.line(
                "pillar",
                p(g.roof_rear_x, y, g.roof_z),
                p(g.c_pillar_foot_x, y, g.shelf_z),
                &s.c_pillar,
                "c_pillar",
                body,
                0.0,
                None,
            )?;
            self.line(
                "roof_rail",
                p(g.roof_rear_x, y, g.roof_z),
                p(g.roof_front_x, y, g.roof_z),
                &s.roof_rail,
                "roof_rail",
                body,
                roof_trim,
                None,
            )?;
        }
        self.line(
            "tunnel",
            p(g.rear_x, 0.0, g.floor_z),
            p(g.firewall_x, 0.0, g.floor_z),
            &s.tunnel,
            "tunnel",
            body,
            floor_trim,
            None,
        )?;
        for &x in &g.cross_member_x {
            self.line(
                "cross_member",
                p(x, -w, g.floor_z),
                p(x, w, g.floor_z),
                &s.cross_member,
                "cross_member",
                body,
                floor_trim,
                None,
            )?;
        }
        self.line(
            "rear_cross_member",
            p(g.rear_x, -w, g.floor_z),
            p(g.rear_x, w, g.floor_z),
            &s.cross_member,
            "rear_cross_member",
            body,
            rear_trim,
            None,
        )?;
        for z in [g.girder_z, g.apron_top_z] {
            self.line(
                region::FRONT_END,
                p(g.front_x, -g.girder_y, z),
                p(g.front_x, g.girder_y, z),
                &s.front_cross,
                "front_cross",
                body,
                front_trim,
                None,
            )?;
        }
        self.line(
            "cowl",
            p(g.cowl_x, -w, g.cowl_z),
            p(g.cowl_x, w, g.cowl_z),
            &s.cross_car_beam,
            "cross_car_beam",
            body,
            dash_trim,
            None,
        )?;
        self.line(
            "cowl",
            p(g.cowl_x, 0.0, g.cowl_z),
            p(g.cowl_x, 0.0, g.floor_z),
            &s.dash_brace,
            "dash_brace",
            body,
            0.0,
            None,
        )?;
        for &x in &g.roof_bow_x {
            self.line(
                region::ROOF,
                p(x, -w, g.roof_z),
                p(x, w, g.roof_z),
                &s.roof_bow,
                "roof_bow",
                body,
                roof_trim,
                None,
            )?;
        }
        self.line(
            "shelf",
            p(g.shelf_x, -w, g.shelf_z),
            p(g.shelf_x, w, g.shelf_z),
            &s.shelf_beam,
            "shelf_beam",
            body,
            0.0,
            None,
        )?;
        if cfg.options.stiffening_bar {
            let x = cfg.options.stiffening_bar_x;
            self.existing(
                p(x, g.girder_y, g.girder_z),
                "stiffening bar end (options.stiffening_bar_x)",
            )?;
            self.line(
                region::FRONT_END,
                p(x, -g.girder_y, g.girder_z),
                p(x, g.girder_y, g.girder_z),
                &s.stiffening_bar,
                "stiffening_bar",
                body,
                0.0,
                None,
            )?;
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
        let column = self.cfg.material;
        self.line(
            "column_lower",
            base,
            support,
            &st.column_section,
            "steering.column_section",
            column,
            0.0,
            Some(n),
        )?;
        self.line(
            region::STEERING,
            support,
            wheel,
            &st.column_section,
            "steering.column_section",
            column,
            0.0,
            Some(n),
        )?;
        self.line(
            "column_bracket",
            support,
            above,
            &st.bracket_section,
            "steering.bracket_section",
            self.body,
            0.0,
            Some(1),
        )?;
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
            let link = self.cfg.sections.wheel_link;
            let ids = self.line(
                "suspension",
                attach,
                centre,
                &link,
                "wheel_link",
                self.body,
                0.0,
                Some(1),
            )?;
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

fn validate(cfg: &ChassisConfig) -> Result<(), FeError> {
    let g = &cfg.geometry;
    let positive = [
        ("geometry.grid_dx", g.grid_dx),
        ("geometry.grid_dy", g.grid_dy),
        ("geometry.grid_dz", g.grid_dz),
        ("geometry.half_width", g.half_width),
        ("geometry.wheelbase", g.wheelbase),
        ("body_stiffness_scale", cfg.body_stiffness_scale),
        ("options.front_plate_factor", cfg.options.front_plate_factor),
        ("steering.wheel_mass", cfg.steering.wheel_mass),
        ("suspension.wheel_rate", cfg.suspension.wheel_rate),
        ("suspension.tyre_rate", cfg.suspension.tyre_rate),
    ];
    for (name, v) in positive {
        super::error::require_positive(name, v)?;
    }
    let on_grid = |name: &str, v: f64, step: f64| -> Result<(), FeError> {
        let r = v / step;
        if v.is_finite() && (r - r.round()).abs() < 1e-6 {
            Ok(())
        } else {
            Err(FeError::InvalidInput(format!(
                "{name} = {v} is not a multiple of the grid spacing {step}"
            )))
        }
    };
    for (name, v) in [
        ("geometry.firewall_x", g.firewall_x),
        ("geometry.rear_x", g.rear_x),
        ("geometry.front_x", g.front_x),
        ("geometry.cowl_x", g.cowl_x),
        ("geometry.roof_front_x", g.roof_front_x),
        ("geometry.roof_rear_x", g.roof_rear_x),
        ("geometry.b_pillar_x", g.b_pillar_x),
        ("geometry.quarter_front_x", g.quarter_front_x),
        ("geometry.shelf_x", g.shelf_x),
        ("mounts.front_x", cfg.mounts.front_x),
        ("mounts.rear_x", cfg.mounts.rear_x),
    ] {
        on_grid(name, v, g.grid_dx)?;
    }
    for (name, v) in [
        ("geometry.half_width", g.half_width),
        ("geometry.girder_y", g.girder_y),
    ] {
        on_grid(name, v, g.grid_dy)?;
    }
    // Heights are measured on the grid from the floor.
    for (name, v) in [
        ("geometry.cowl_z", g.cowl_z),
        ("geometry.shelf_z", g.shelf_z),
        ("geometry.girder_z", g.girder_z),
        ("geometry.apron_top_z", g.apron_top_z),
    ] {
        on_grid(name, v - g.floor_z, g.grid_dz)?;
    }
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
    for (what, ok) in ordered {
        if !ok {
            return Err(FeError::InvalidInput(format!(
                "geometry must satisfy {what}"
            )));
        }
    }
    for (name, list, lo, hi) in [
        (
            "geometry.cross_member_x",
            &g.cross_member_x,
            g.rear_x,
            g.firewall_x,
        ),
        (
            "geometry.roof_bow_x",
            &g.roof_bow_x,
            g.roof_rear_x,
            g.roof_front_x,
        ),
    ] {
        for &x in list.iter() {
            on_grid(name, x, g.grid_dx)?;
            if !(lo..=hi).contains(&x) {
                return Err(FeError::InvalidInput(format!(
                    "{name} entry {x} lies outside its panel ({lo} ..= {hi})"
                )));
            }
        }
    }
    if !MOUNT_NAMES.contains(&cfg.mounts.removed_in_three_mount_layout.as_str()) {
        return Err(FeError::InvalidInput(format!(
            "mounts.removed_in_three_mount_layout = '{}' must be one of {MOUNT_NAMES:?}",
            cfg.mounts.removed_in_three_mount_layout
        )));
    }
    Ok(())
}
