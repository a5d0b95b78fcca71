//! Linearisation at the static equilibrium and modal analysis (paper Table 1).
//!
//! `A = M⁻¹ ∂f/∂(q, v)` by central differences of the right-hand side with the engine at rest
//! (crank standing, no gas, mounts linearised at the operating point), eigenvalues of the
//! state-space matrix with faer's dense eigen solver: frequency `|λ|/2π`, damping `−Re λ/|λ|`.
//!
//! Mode description: the strain energy of the mode shape decides between a rigid-body mode
//! (mounts strained most) and a ring-carrier mode (ring carriers strained most). Rigid-body modes
//! are named by the direction with the largest kinetic energy, in the paper's naming for the
//! transverse engine: lateral = translation x, axial = translation along the crank axis y,
//! vertical = z, pitching = rotation about x, rolling = about the crank axis y, yawing = about z.
//! Ring-carrier modes are named by the most strained bushing and direction.

use faer::linalg::solvers::Solve;
use faer::Mat;
use nalgebra::Vector3;

use super::ground_scene::GroundScene;
use crate::ode::OdeProblem;

/// Direction of a body motion, vehicle axes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Direction {
    /// Translation x ("lateral" for the transverse engine).
    Lateral,
    /// Translation y, along the crank axis ("axial").
    Axial,
    /// Translation z.
    Vertical,
    /// Rotation about x ("pitching").
    Pitch,
    /// Rotation about the crank axis y ("rolling").
    Roll,
    /// Rotation about z ("yawing").
    Yaw,
}

impl Direction {
    fn from_index(i: usize) -> Self {
        [
            Self::Lateral,
            Self::Axial,
            Self::Vertical,
            Self::Pitch,
            Self::Roll,
            Self::Yaw,
        ][i.min(5)]
    }

    /// The paper's wording.
    pub fn paper_name(&self) -> &'static str {
        match self {
            Self::Lateral => "lateral translation (x)",
            Self::Axial => "axial translation (y, crank axis)",
            Self::Vertical => "vertical translation (z)",
            Self::Pitch => "pitching (about x)",
            Self::Roll => "rolling (about crank axis y)",
            Self::Yaw => "yawing (about z)",
        }
    }
}

/// What a mode mostly is.
#[derive(Debug, Clone, PartialEq)]
pub enum ModeKind {
    /// The powertrain moves as a whole on its mounts.
    RigidBody(Direction),
    /// Monoblock against housing; `bushing` is the most strained ring carrier, `direction` its
    /// most strained local direction (translations and rotations as in [`Direction`]).
    RingCarrier {
        bushing: String,
        direction: Direction,
    },
}

/// One eigenmode of the linearised engine.
#[derive(Debug, Clone, PartialEq)]
pub struct Mode {
    pub frequency_hz: f64,
    pub damping_ratio: f64,
    pub kind: ModeKind,
    pub description: String,
    /// Kinetic energy fractions per body (name) and direction `[x, y, z, rx, ry, rz]`.
    pub kinetic_fractions: Vec<(String, [f64; 6])>,
    /// Strain energy fraction in the mounts (the rest is in the ring carriers).
    pub mount_strain_fraction: f64,
}

fn describe(kind: &ModeKind) -> String {
    match kind {
        ModeKind::RigidBody(d) => format!("{} of engine assembly", d.paper_name()),
        ModeKind::RingCarrier { bushing, direction } => match direction {
            Direction::Axial => "axial deformation of ring carriers".to_string(),
            Direction::Roll => "torsion deformation of ring carriers".to_string(),
            Direction::Vertical | Direction::Pitch => {
                format!("{bushing} ring carrier, ajar vertical")
            }
            Direction::Lateral | Direction::Yaw => format!("{bushing} ring carrier, ajar lateral"),
        },
    }
}

pub(crate) type C = (f64, f64);

/// Eigenpairs `(λ, x)` of the state matrix `a` with `Im λ > 0`: one per oscillatory mode (its
/// conjugate and the real, non-oscillating eigenvalues are dropped, as are rigid-body zeros).
pub(crate) fn oscillatory_eigenpairs(a: &Mat<f64>) -> Result<Vec<(C, Vec<C>)>, String> {
    let n = a.nrows();
    let eig = a
        .eigen()
        .map_err(|e| format!("eigen solver failed: {e:?}"))?;
    let s = eig.S();
    let u = eig.U();
    let mut pairs = Vec::new();
    for k in 0..n {
        let (re, im) = (s[k].re, s[k].im);
        let mag = re.hypot(im);
        if im <= 1e-6 * mag.max(1.0) || mag < 1e-3 {
            continue;
        }
        pairs.push((
            (re, im),
            (0..n).map(|i| (u[(i, k)].re, u[(i, k)].im)).collect(),
        ));
    }
    Ok(pairs)
}

fn cmul(a: C, b: C) -> C {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

fn abs2(a: C) -> f64 {
    a.0 * a.0 + a.1 * a.1
}

/// Complex small displacement of a point `r` (vehicle frame, from the reference point) for
/// translation `u` and rotation `θ` (both complex 3-vectors).
fn point_motion(u: &[C], th: &[C], r: &Vector3<f64>) -> [C; 3] {
    let cross = |a: [C; 3]| -> [C; 3] {
        [
            (a[1].0 * r.z - a[2].0 * r.y, a[1].1 * r.z - a[2].1 * r.y),
            (a[2].0 * r.x - a[0].0 * r.z, a[2].1 * r.x - a[0].1 * r.z),
            (a[0].0 * r.y - a[1].0 * r.x, a[0].1 * r.y - a[1].1 * r.x),
        ]
    };
    let c = cross([th[0], th[1], th[2]]);
    [
        (u[0].0 + c[0].0, u[0].1 + c[0].1),
        (u[1].0 + c[1].0, u[1].1 + c[1].1),
        (u[2].0 + c[2].0, u[2].1 + c[2].1),
    ]
}

impl GroundScene {
    /// Eigenmodes at the equilibrium state `y_eq` (from [`GroundScene::static_equilibrium`]),
    /// sorted by frequency; overdamped and static (zero) eigenvalues are skipped.
    pub fn modes(&self, y_eq: &[f64]) -> Result<Vec<Mode>, String> {
        self.check_state(y_eq).map_err(|e| format!("{e:?}"))?;
        let nb = self.body_count();
        let n = 12 * nb;
        let dim = self.dim();
        let mut jac = Mat::<f64>::zeros(n, n);
        let mut fp = vec![0.0; dim];
        let mut fm = vec![0.0; dim];
        for j in 0..n {
            let h = 1e-7;
            let mut yp = y_eq.to_vec();
            yp[j] += h;
            let mut ym = y_eq.to_vec();
            ym[j] -= h;
            self.rhs_at_rest(&yp, &mut fp)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            self.rhs_at_rest(&ym, &mut fm)
                .map_err(|e| format!("linearisation failed: {e:?}"))?;
            for i in 0..n {
                jac[(i, j)] = (fp[i] - fm[i]) / (2.0 * h);
            }
        }
        let masses = self.body_mass(0.0, y_eq);
        let mut mass = Mat::<f64>::identity(n, n);
        for (b, m) in masses.iter().enumerate() {
            let o = 6 * nb + 6 * b;
            for i in 0..6 {
                for j in 0..6 {
                    mass[(o + i, o + j)] = m[(i, j)];
                }
            }
        }
        let a = mass.partial_piv_lu().solve(&jac);
        let mut modes: Vec<Mode> = oscillatory_eigenpairs(&a)?
            .into_iter()
            .map(|(lam, x)| self.describe_mode(y_eq, &x, lam, &masses))
            .collect();
        modes.sort_by(|a, b| a.frequency_hz.total_cmp(&b.frequency_hz));
        Ok(modes)
    }

    fn describe_mode(
        &self,
        y_eq: &[f64],
        x: &[C],
        lam: C,
        masses: &[nalgebra::Matrix6<f64>],
    ) -> Mode {
        let nb = self.body_count();
        let mag = lam.0.hypot(lam.1);
        // Kinetic energy per body and direction from the velocity part of the mode shape.
        let mut kinetic = Vec::new();
        let mut total_kinetic = 0.0;
        for b in 0..nb {
            let v: Vec<C> = (0..6).map(|i| x[6 * nb + 6 * b + i]).collect();
            let mut e = [0.0; 6];
            for i in 0..6 {
                let mut mv = (0.0, 0.0);
                for j in 0..6 {
                    mv.0 += masses[b][(i, j)] * v[j].0;
                    mv.1 += masses[b][(i, j)] * v[j].1;
                }
                let p = cmul((v[i].0, -v[i].1), mv);
                e[i] = p.0.max(0.0);
                total_kinetic += e[i];
            }
            kinetic.push((self.bodies()[b].name.clone(), e));
        }
        for (_, e) in &mut kinetic {
            for v in e.iter_mut() {
                *v /= total_kinetic.max(f64::MIN_POSITIVE);
            }
        }
        // Strain energies from the displacement part.
        let disp = |b: usize| -> (Vec<C>, Vec<C>) {
            (
                (0..3).map(|i| x[6 * b + i]).collect(),
                (3..6).map(|i| x[6 * b + i]).collect(),
            )
        };
        let hb = self.housing_index();
        let kin_h = self.kinematics(y_eq, hb);
        let (uh, th_h) = disp(hb);
        let mut mount_strain = 0.0;
        for (i, m) in self.mounts().iter().enumerate() {
            let Some(m) = m else { continue };
            let r = kin_h.rotation * (m.bracket - self.bodies()[hb].reference);
            let d = point_motion(&uh, &th_h, &r);
            let scale = self.inputs().stiffness_scale[i];
            for axis in 0..3 {
                let a = m.axes.row(axis);
                let local = (
                    a[0] * d[0].0 + a[1] * d[1].0 + a[2] * d[2].0,
                    a[0] * d[0].1 + a[1] * d[1].1 + a[2] * d[2].1,
                );
                mount_strain +=
                    0.5 * scale * m.curves[axis].stiffness(m.operating_point[axis]) * abs2(local);
            }
        }
        let mut ring_strain = 0.0;
        let mut best: (f64, String, usize) = (0.0, String::new(), 0);
        if nb == 2 {
            let kin_m = self.kinematics(y_eq, 0);
            let (um, th_m) = disp(0);
            for rc in self.ring_carriers() {
                let dm = point_motion(&um, &th_m, &(kin_m.rotation * rc.on_monoblock));
                let dh = point_motion(&uh, &th_h, &(kin_h.rotation * rc.on_housing));
                let rel: Vec<C> = (0..6)
                    .map(|i| {
                        if i < 3 {
                            (dm[i].0 - dh[i].0, dm[i].1 - dh[i].1)
                        } else {
                            (th_m[i - 3].0 - th_h[i - 3].0, th_m[i - 3].1 - th_h[i - 3].1)
                        }
                    })
                    .collect();
                for (i, r) in rel.iter().enumerate() {
                    let e = 0.5 * rc.stiffness[i] * abs2(*r);
                    ring_strain += e;
                    if e > best.0 {
                        best = (e, rc.name.clone(), i);
                    }
                }
            }
        }
        let kind = if ring_strain > mount_strain {
            ModeKind::RingCarrier {
                bushing: best.1,
                direction: Direction::from_index(best.2),
            }
        } else {
            let mut per_dir = [0.0; 6];
            for (_, e) in &kinetic {
                for i in 0..6 {
                    per_dir[i] += e[i];
                }
            }
            let dominant = (0..6)
                .max_by(|&a, &b| per_dir[a].total_cmp(&per_dir[b]))
                .unwrap_or(0);
            ModeKind::RigidBody(Direction::from_index(dominant))
        };
        Mode {
            frequency_hz: mag / (2.0 * std::f64::consts::PI),
            damping_ratio: -lam.0 / mag,
            description: describe(&kind),
            kind,
            kinetic_fractions: kinetic,
            mount_strain_fraction: mount_strain
                / (mount_strain + ring_strain).max(f64::MIN_POSITIVE),
        }
    }
}

/// Formats modes as a table like the paper's Table 1 (with energy fractions).
pub fn mode_table(modes: &[Mode]) -> String {
    let mut s = String::from("  f [Hz]   zeta [%]  mount strain [%]  description                                   dominant kinetic energy\n");
    for m in modes {
        let mut dom = (0.0, String::new());
        for (body, e) in &m.kinetic_fractions {
            for (i, v) in e.iter().enumerate() {
                if *v > dom.0 {
                    dom = (
                        *v,
                        format!("{body} {}", ["x", "y", "z", "rx", "ry", "rz"][i]),
                    );
                }
            }
        }
        s += &format!(
            "{:8.2}  {:8.2}  {:16.1}  {:<44}  {} {:.0} %\n",
            m.frequency_hz,
            100.0 * m.damping_ratio,
            100.0 * m.mount_strain_fraction,
            m.description,
            dom.1,
            100.0 * dom.0
        );
    }
    s
}
