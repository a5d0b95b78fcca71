//! Coupled linearised modal analysis of engine and chassis (paper Table 1, middle column).
//!
//! The hybrid right-hand side with the engine at rest (crank standing, no gas, mounts linearised
//! at the coupled static equilibrium) is differentiated by central differences with respect to
//! the engine coordinates and velocities and the chassis modal coordinates and rates (the crank
//! angle is not a vibration coordinate); the right-hand side is explicit, so the eigenvalues of
//! `∂f/∂y` give frequency `|λ|/2π` and damping `−Re λ/|λ|`.
//!
//! Each mode is described by where its kinetic energy sits: an engine mode (more than half of
//! the kinetic energy in the powertrain) is a rigid-body or ring-carrier mode as in
//! [`super::modes`] (whichever of mounts and ring carriers is strained more), named by its
//! dominant direction; a chassis mode is named by the uncoupled chassis mode that carries most of
//! its energy and the recovery point that moves most.

use faer::Mat;
use nalgebra::{Matrix6, Vector3};

use super::hybrid_scene::HybridScene;
use super::modes::{oscillatory_eigenpairs, Direction, ModeKind, C};
use crate::ode::OdeProblem;

const DIRECTIONS: [Direction; 6] = [
    Direction::Lateral,
    Direction::Axial,
    Direction::Vertical,
    Direction::Pitch,
    Direction::Roll,
    Direction::Yaw,
];

/// What a coupled mode mostly is.
#[derive(Debug, Clone, PartialEq)]
pub enum HybridModeKind {
    /// Most kinetic energy in the powertrain.
    Engine(ModeKind),
    /// Most kinetic energy in the chassis: `mode` is the uncoupled chassis mode contributing most,
    /// `point` the recovery point with the largest translation.
    Chassis {
        mode: usize,
        uncoupled_hz: f64,
        point: String,
    },
}

/// One eigenmode of the linearised engine-in-chassis model.
#[derive(Debug, Clone, PartialEq)]
pub struct HybridMode {
    pub frequency_hz: f64,
    pub damping_ratio: f64,
    pub kind: HybridModeKind,
    pub description: String,
    /// Share of the kinetic energy in the powertrain (the rest is in the chassis).
    pub engine_kinetic_fraction: f64,
    /// Powertrain kinetic energy per direction `[x, y, z, rx, ry, rz]`, fractions of the
    /// powertrain's kinetic energy.
    pub engine_directions: [f64; 6],
}

fn abs2(a: C) -> f64 {
    a.0 * a.0 + a.1 * a.1
}

fn sub3(a: [C; 3], b: [C; 3]) -> [C; 3] {
    [
        (a[0].0 - b[0].0, a[0].1 - b[0].1),
        (a[1].0 - b[1].0, a[1].1 - b[1].1),
        (a[2].0 - b[2].0, a[2].1 - b[2].1),
    ]
}

/// Small complex displacement of a body point at lever `r` for translation `u`, rotation `th`.
fn point_motion(u: &[C], th: &[C], r: &Vector3<f64>) -> [C; 3] {
    let c = |a: usize, b: usize, ra: f64, rb: f64| {
        (th[a].0 * rb - th[b].0 * ra, th[a].1 * rb - th[b].1 * ra)
    };
    let cx = c(1, 2, r.y, r.z);
    let cy = c(2, 0, r.z, r.x);
    let cz = c(0, 1, r.x, r.y);
    [
        (u[0].0 + cx.0, u[0].1 + cx.1),
        (u[1].0 + cy.0, u[1].1 + cy.1),
        (u[2].0 + cz.0, u[2].1 + cz.1),
    ]
}

impl HybridScene {
    /// Coupled eigenmodes at the equilibrium `y_eq` (from [`HybridScene::static_equilibrium`]),
    /// sorted by frequency; overdamped and static eigenvalues are skipped.
    pub fn modes(&self, y_eq: &[f64]) -> Result<Vec<HybridMode>, String> {
        self.check_state(y_eq).map_err(|e| format!("{e:?}"))?;
        let engine = self.engine();
        let nb = engine.body_count();
        let ne = self.engine_dim();
        let m = self.modes_count();
        // Vibration coordinates: engine q and v, chassis η and η̇ (not the crank angle).
        let coords: Vec<usize> = (0..12 * nb).chain(ne..ne + 2 * m).collect();
        let n = coords.len();
        let dim = self.dim();
        let mut jac = Mat::<f64>::zeros(n, n);
        let mut fp = vec![0.0; dim];
        let mut fm = vec![0.0; dim];
        let mut y = y_eq.to_vec();
        for (c, &jc) in coords.iter().enumerate() {
            let h = 1e-7;
            y[jc] = y_eq[jc] + h;
            self.rhs_at_rest(&y, &mut fp)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            y[jc] = y_eq[jc] - h;
            self.rhs_at_rest(&y, &mut fm)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            y[jc] = y_eq[jc];
            for (r, &ir) in coords.iter().enumerate() {
                jac[(r, c)] = (fp[ir] - fm[ir]) / (2.0 * h);
            }
        }
        // The right-hand side is already explicit (engine rows are accelerations): A = ∂f/∂y.
        let masses: Vec<Matrix6<f64>> = engine.body_mass(engine.fade_start(), &y_eq[..ne]);
        let mut modes: Vec<HybridMode> = oscillatory_eigenpairs(&jac)?
            .into_iter()
            .map(|(lam, x)| self.describe_mode(y_eq, &x, lam, &masses))
            .collect();
        modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        Ok(modes)
    }

    /// `x` is a mode shape over `[engine q, engine v, η, η̇]`.
    fn describe_mode(&self, y_eq: &[f64], x: &[C], lam: C, masses: &[Matrix6<f64>]) -> HybridMode {
        let engine = self.engine();
        let nb = engine.body_count();
        let m = self.modes_count();
        let (eta, eta_rate) = (12 * nb, 12 * nb + m);
        let mag = lam.0.hypot(lam.1);

        let mut directions = [0.0; 6];
        let mut engine_kinetic = 0.0;
        for (b, mb) in masses.iter().enumerate() {
            let v: Vec<C> = (0..6).map(|i| x[6 * nb + 6 * b + i]).collect();
            for i in 0..6 {
                let mut mv = (0.0, 0.0);
                for j in 0..6 {
                    mv.0 += mb[(i, j)] * v[j].0;
                    mv.1 += mb[(i, j)] * v[j].1;
                }
                let e = (v[i].0 * mv.0 + v[i].1 * mv.1).max(0.0);
                directions[i] += e;
                engine_kinetic += e;
            }
        }
        let modal_kinetic: Vec<f64> = (0..m).map(|k| abs2(x[eta_rate + k])).collect();
        let chassis_kinetic: f64 = modal_kinetic.iter().sum();
        let total = (engine_kinetic + chassis_kinetic).max(f64::MIN_POSITIVE);
        for d in directions.iter_mut() {
            *d /= engine_kinetic.max(f64::MIN_POSITIVE);
        }
        let engine_fraction = engine_kinetic / total;
        let eta_shape: Vec<C> = (0..m).map(|k| x[eta + k]).collect();

        let kind = if engine_fraction >= 0.5 {
            HybridModeKind::Engine(self.engine_mode_kind(y_eq, x, &eta_shape, &directions))
        } else {
            let dominant = (0..m)
                .max_by(|&a, &b| modal_kinetic[a].total_cmp(&modal_kinetic[b]))
                .unwrap_or(0);
            let chassis = self.chassis();
            let point = (0..chassis.points.len())
                .map(|p| {
                    let mut amp = [(0.0, 0.0); 3];
                    for (s, e) in chassis.points[p].shape.iter().zip(&eta_shape) {
                        for i in 0..3 {
                            amp[i].0 += s[i] * e.0;
                            amp[i].1 += s[i] * e.1;
                        }
                    }
                    (p, amp.iter().map(|a| abs2(*a)).sum::<f64>())
                })
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(p, _)| chassis.points[p].name.clone())
                .unwrap_or_default();
            HybridModeKind::Chassis {
                mode: dominant,
                uncoupled_hz: chassis.omega[dominant] / (2.0 * std::f64::consts::PI),
                point,
            }
        };
        let description = match &kind {
            HybridModeKind::Engine(ModeKind::RigidBody(d)) => {
                format!("{} of engine assembly", d.paper_name())
            }
            HybridModeKind::Engine(ModeKind::RingCarrier { bushing, direction }) => {
                format!("ring carrier {bushing}: {}", direction.paper_name())
            }
            HybridModeKind::Chassis {
                mode,
                uncoupled_hz,
                point,
            } => format!(
                "chassis mode {mode} ({uncoupled_hz:.2} Hz alone), largest motion at {point}"
            ),
        };
        HybridMode {
            frequency_hz: mag / (2.0 * std::f64::consts::PI),
            damping_ratio: -lam.0 / mag,
            kind,
            description,
            engine_kinetic_fraction: engine_fraction,
            engine_directions: directions,
        }
    }

    /// Rigid-body or ring-carrier mode, by whichever of mounts and ring carriers strains more.
    fn engine_mode_kind(
        &self,
        y_eq: &[f64],
        x: &[C],
        eta_shape: &[C],
        directions: &[f64; 6],
    ) -> ModeKind {
        let engine = self.engine();
        let nb = engine.body_count();
        let ne = self.engine_dim();
        let disp = |b: usize| -> (Vec<C>, Vec<C>) {
            (
                (0..3).map(|i| x[6 * b + i]).collect(),
                (3..6).map(|i| x[6 * b + i]).collect(),
            )
        };
        let hb = engine.housing_index();
        let kin_h = engine.kinematics(&y_eq[..ne], hb);
        let (uh, th_h) = disp(hb);
        let chassis = self.chassis();
        let mut mount_strain = 0.0;
        for (i, mount, p) in self.connected_mounts() {
            let r = kin_h.rotation * (mount.bracket - engine.bodies()[hb].reference);
            let mut attach = [(0.0, 0.0); 3];
            for (s, e) in chassis.points[p].shape.iter().zip(eta_shape) {
                for a in 0..3 {
                    attach[a].0 += s[a] * e.0;
                    attach[a].1 += s[a] * e.1;
                }
            }
            let d = sub3(point_motion(&uh, &th_h, &r), attach);
            let scale = engine.inputs().stiffness_scale[i];
            for axis in 0..3 {
                let ax = mount.axes.row(axis);
                let local = (
                    ax[0] * d[0].0 + ax[1] * d[1].0 + ax[2] * d[2].0,
                    ax[0] * d[0].1 + ax[1] * d[1].1 + ax[2] * d[2].1,
                );
                let k = mount.curves[axis].stiffness(mount.operating_point[axis]);
                mount_strain += 0.5 * scale * k * abs2(local);
            }
        }
        let mut ring_strain = 0.0;
        let mut best: (f64, String, usize) = (0.0, String::new(), 0);
        if nb == 2 {
            let kin_m = engine.kinematics(&y_eq[..ne], 0);
            let (um, th_m) = disp(0);
            for rc in engine.ring_carriers() {
                let dm = point_motion(&um, &th_m, &(kin_m.rotation * rc.on_monoblock));
                let dh = point_motion(&uh, &th_h, &(kin_h.rotation * rc.on_housing));
                let rel = sub3(dm, dh);
                for i in 0..6 {
                    let r = if i < 3 {
                        rel[i]
                    } else {
                        (th_m[i - 3].0 - th_h[i - 3].0, th_m[i - 3].1 - th_h[i - 3].1)
                    };
                    let e = 0.5 * rc.stiffness[i] * abs2(r);
                    ring_strain += e;
                    if e > best.0 {
                        best = (e, rc.name.clone(), i);
                    }
                }
            }
        }
        if ring_strain > mount_strain {
            ModeKind::RingCarrier {
                bushing: best.1,
                direction: DIRECTIONS[best.2],
            }
        } else {
            let dominant = (0..6)
                .max_by(|&a, &b| directions[a].total_cmp(&directions[b]))
                .unwrap_or(0);
            ModeKind::RigidBody(DIRECTIONS[dominant])
        }
    }
}

/// Formats coupled modes as a table.
pub fn hybrid_mode_table(modes: &[HybridMode]) -> String {
    let mut s = String::from("  f [Hz]  zeta [%]  engine KE [%]  description\n");
    for m in modes {
        s += &format!(
            "{:8.2}  {:8.2}  {:13.0}  {}\n",
            m.frequency_hz,
            100.0 * m.damping_ratio,
            100.0 * m.engine_kinetic_fraction,
            m.description
        );
    }
    s
}
