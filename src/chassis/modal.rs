//! Mode descriptions: what a mode shape of the body does, from kinetic-energy fractions in named
//! regions, a rigid-body fit, the twist between the front and rear body sections and the
//! vertical bending of the sills.

use std::collections::BTreeMap;

use nalgebra::{Matrix6, Vector3, Vector6};

use super::body::{region, STEERING_WHEEL};
use crate::eigen::Modes;
use crate::fe::assembly::{mat_vec, Assembled};
use crate::fe::dof::Expansion;
use crate::fe::error::FeError;
use crate::fe::mesh::Mesh;

/// What a mode is.
#[derive(Debug, Clone, PartialEq)]
pub enum ModeKind {
    /// The body moves as a rigid body on its suspension (label: dominant motion).
    RigidBody(String),
    /// Global torsion: front and rear body sections twist against each other about x.
    GlobalTorsion,
    /// Global vertical bending of the body.
    GlobalBending,
    /// Steering column and wheel, predominantly vertical.
    SteeringWheelVertical,
    /// Steering column and wheel, predominantly lateral.
    SteeringWheelLateral,
    /// Steering column dominant, the wheel rotating rather than translating.
    SteeringColumn,
    /// Front end (girders, aprons) dominant.
    FrontEnd,
    /// Local mode of the named region.
    Local(String),
}

/// Description of one mode.
#[derive(Debug, Clone, PartialEq)]
pub struct ModeDescription {
    /// Mode number (0-based, ascending frequency).
    pub index: usize,
    /// Natural frequency (Hz).
    pub frequency_hz: f64,
    /// Classification.
    pub kind: ModeKind,
    /// Kinetic-energy fraction per region (regions overlap; `body` is everything but the column).
    pub energy: BTreeMap<String, f64>,
    /// Twist between front and rear sections × half width, relative to the largest body
    /// translation (≈ 1 for a pure torsion mode, ≈ 0 for others).
    pub twist: f64,
    /// Vertical bending signature: front end and rear panel moving together against the middle of
    /// the sills, relative to the largest body translation (0 when the signature is absent).
    pub bending: f64,
    /// Fraction of the body translation not explained by a rigid-body motion.
    pub elastic: f64,
    /// Share of the kinetic energy in the vertical (z) translation of the steering-wheel node.
    pub wheel_vertical: f64,
    /// Share of the kinetic energy in the lateral (y) translation of the steering-wheel node.
    pub wheel_lateral: f64,
}

impl ModeDescription {
    /// What the mode is, in words ("global torsion", "steering wheel vertical", …).
    pub fn kind_label(&self) -> String {
        match &self.kind {
            ModeKind::RigidBody(s) => format!("rigid body on suspension: {s}"),
            ModeKind::GlobalTorsion => "global torsion".into(),
            ModeKind::GlobalBending => "global bending".into(),
            ModeKind::SteeringWheelVertical => "steering wheel vertical".into(),
            ModeKind::SteeringWheelLateral => "steering wheel lateral".into(),
            ModeKind::SteeringColumn => "steering column (wheel rotation)".into(),
            ModeKind::FrontEnd => "front end".into(),
            ModeKind::Local(r) => format!("local: {r}"),
        }
    }

    /// One-line human-readable summary.
    pub fn summary(&self) -> String {
        let kind = self.kind_label();
        format!(
            "{:3} {:8.2} Hz  {:<38} steering {:4.2} (wheel z {:4.2} y {:4.2}) front {:4.2} \
             twist {:4.2} bend {:4.2}",
            self.index + 1,
            self.frequency_hz,
            kind,
            self.energy.get(region::STEERING).copied().unwrap_or(0.0),
            self.wheel_vertical,
            self.wheel_lateral,
            self.energy.get(region::FRONT_END).copied().unwrap_or(0.0),
            self.twist,
            self.bending,
        )
    }
}

fn translation(asm: &Assembled, shape: &[f64], node: usize) -> Vector3<f64> {
    let mut u = Vector3::zeros();
    for d in 0..3 {
        // A node on a rigid/interpolation link moves with its row of T.
        u[d] = match asm.dofs.expansion(node, d) {
            Some(Expansion::Equation(g)) => shape[g],
            Some(Expansion::Combination(row)) => row.iter().map(|&(g, c)| c * shape[g]).sum(),
            _ => 0.0,
        };
    }
    u
}

/// Least-squares rotation about the x axis of a cross-section (nodes), about its centroid.
fn section_roll(mesh: &Mesh, asm: &Assembled, shape: &[f64], nodes: &[usize]) -> f64 {
    let n = nodes.len().max(1) as f64;
    let (cy, cz) = nodes.iter().fold((0.0, 0.0), |(y, z), &i| {
        (y + mesh.nodes[i].y, z + mesh.nodes[i].z)
    });
    let (cy, cz) = (cy / n, cz / n);
    let (mut num, mut den) = (0.0, 0.0);
    for &i in nodes {
        let (y, z) = (mesh.nodes[i].y - cy, mesh.nodes[i].z - cz);
        let u = translation(asm, shape, i);
        num += y * u.z - z * u.y;
        den += y * y + z * z;
    }
    if den > 0.0 {
        num / den
    } else {
        0.0
    }
}

/// Fraction of the translations of `nodes` not explained by a best-fit rigid-body motion.
fn elastic_fraction(mesh: &Mesh, asm: &Assembled, shape: &[f64], nodes: &[usize]) -> f64 {
    let n = nodes.len().max(1) as f64;
    let c = nodes
        .iter()
        .fold(Vector3::zeros(), |a, &i| a + mesh.nodes[i])
        / n;
    let mut ata = Matrix6::zeros();
    let mut atb = Vector6::zeros();
    let mut total = 0.0;
    for &i in nodes {
        let r = mesh.nodes[i] - c;
        let u = translation(asm, shape, i);
        total += u.norm_squared();
        // u ≈ t + ω × r: rows for the three components.
        for d in 0..3 {
            let mut row = Vector6::zeros();
            row[d] = 1.0;
            let e = Vector3::ith(d, 1.0);
            // (ω × r)_d = ω · (r × e_d)
            let w = r.cross(&e);
            row[3] = w.x;
            row[4] = w.y;
            row[5] = w.z;
            ata += row * row.transpose();
            atb += row * u[d];
        }
    }
    let Some(x) = ata.try_inverse().map(|inv| inv * atb) else {
        return 1.0;
    };
    let mut residual = 0.0;
    for &i in nodes {
        let r = mesh.nodes[i] - c;
        let t = Vector3::new(x[0], x[1], x[2]);
        let w = Vector3::new(x[3], x[4], x[5]);
        residual += (translation(asm, shape, i) - t - w.cross(&r)).norm_squared();
    }
    if total > 0.0 {
        (residual / total).sqrt()
    } else {
        0.0
    }
}

fn rigid_label(mesh: &Mesh, asm: &Assembled, shape: &[f64], nodes: &[usize]) -> String {
    let n = nodes.len().max(1) as f64;
    let mean = nodes
        .iter()
        .fold(Vector3::zeros(), |a, &i| a + translation(asm, shape, i))
        / n;
    let roll = section_roll(mesh, asm, shape, nodes);
    // Pitch and yaw from the first moments of z and y motion along x.
    let cx = nodes.iter().map(|&i| mesh.nodes[i].x).sum::<f64>() / n;
    let (mut pitch_num, mut yaw_num, mut den) = (0.0, 0.0, 0.0);
    for &i in nodes {
        let x = mesh.nodes[i].x - cx;
        let u = translation(asm, shape, i);
        pitch_num += -x * u.z;
        yaw_num += x * u.y;
        den += x * x;
    }
    let half_length = (den / n).sqrt();
    let candidates = [
        ("longitudinal", mean.x.abs()),
        ("lateral", mean.y.abs()),
        ("bounce", mean.z.abs()),
        ("roll", roll.abs() * 0.7),
        ("pitch", (pitch_num / den.max(1e-300)).abs() * half_length),
        ("yaw", (yaw_num / den.max(1e-300)).abs() * half_length),
    ];
    candidates
        .iter()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|c| c.0.to_string())
        .unwrap_or_default()
}

/// The two steering-wheel modes, as indices into `descs`: (more vertical, more lateral).
///
/// They are the two modes with the largest kinetic-energy share in the translation of the
/// steering-wheel node. Their frequencies are close (paper: 31.5 and 32.07 Hz), so through the
/// body they couple and both move the wheel obliquely; "vertical" is the one whose wheel motion
/// is more vertical.
pub fn steering_wheel_pair(descs: &[ModeDescription]) -> Option<(usize, usize)> {
    let wheel = |d: &ModeDescription| d.wheel_vertical + d.wheel_lateral;
    let mut order: Vec<usize> = (0..descs.len()).collect();
    order.sort_by(|&a, &b| wheel(&descs[b]).total_cmp(&wheel(&descs[a])));
    let (&a, &b) = (order.first()?, order.get(1)?);
    if wheel(&descs[b]) <= 0.0 {
        return None;
    }
    let verticality = |i: usize| descs[i].wheel_vertical / wheel(&descs[i]);
    if verticality(a) >= verticality(b) {
        Some((a, b))
    } else {
        Some((b, a))
    }
}

/// Describes every mode of `modes` of the chassis `mesh` assembled as `asm`.
///
/// Long on purpose: one report that walks every mode with shared per-region sums.
pub fn describe(
    mesh: &Mesh,
    asm: &Assembled,
    modes: &Modes,
) -> Result<Vec<ModeDescription>, FeError> {
    let need = |name: &str| {
        mesh.regions
            .get(name)
            .ok_or_else(|| FeError::InvalidInput(format!("mesh has no region '{name}'")))
    };
    if asm.dofs.n_nodes() != mesh.nodes.len() || modes.shapes.nrows() != asm.dofs.n_free() {
        return Err(FeError::InvalidInput(format!(
            "mesh ({} nodes), DOF map ({} nodes, {} DOFs) and mode shapes ({} rows) do not match",
            mesh.nodes.len(),
            asm.dofs.n_nodes(),
            asm.dofs.n_free(),
            modes.shapes.nrows()
        )));
    }
    for (name, nodes) in &mesh.regions {
        if let Some(&bad) = nodes.iter().find(|&&k| k >= mesh.nodes.len()) {
            return Err(FeError::InvalidInput(format!(
                "region '{name}' refers to node {bad}, mesh has {} nodes",
                mesh.nodes.len()
            )));
        }
    }
    let body = need(region::BODY)?;
    let front = need(region::FIREWALL)?;
    let rear = need(region::REAR_PANEL)?;
    let sills = need("sill")?;
    let front_end_nodes = need(region::FRONT_END)?;
    let (x_min, x_max) = sills.iter().fold((f64::MAX, f64::MIN), |(lo, hi), &i| {
        (lo.min(mesh.nodes[i].x), hi.max(mesh.nodes[i].x))
    });
    // The middle third of the sills.
    let (centre, half) = ((x_min + x_max) / 2.0, (x_max - x_min) / 6.0);
    let mid_sill: Vec<usize> = sills
        .iter()
        .copied()
        .filter(|&i| (mesh.nodes[i].x - centre).abs() <= half + 1e-9)
        .collect();
    let wheel = mesh
        .named(STEERING_WHEEL)
        .ok_or_else(|| FeError::InvalidInput("mesh has no named node 'steering_wheel'".into()))?;
    let half_width = body
        .iter()
        .map(|&i| mesh.nodes[i].y.abs())
        .fold(0.0, f64::max);
    let owners = asm.dofs.owners();
    let freqs = modes.frequencies_hz();
    let mut out = Vec::with_capacity(modes.len());
    for (k, &frequency_hz) in freqs.iter().enumerate() {
        let shape: Vec<f64> = modes.shapes.col(k).iter().copied().collect();
        let m_phi = mat_vec(&asm.m, &shape);
        let mut node_energy = vec![0.0; mesh.nodes.len()];
        for (g, &(node, _)) in owners.iter().enumerate() {
            node_energy[node] += shape[g] * m_phi[g];
        }
        let total: f64 = node_energy.iter().sum();
        let mut energy = BTreeMap::new();
        for (name, nodes) in &mesh.regions {
            let e: f64 = nodes.iter().map(|&i| node_energy[i]).sum();
            energy.insert(name.clone(), if total > 0.0 { e / total } else { 0.0 });
        }
        let amplitude = body
            .iter()
            .map(|&i| translation(asm, &shape, i).norm())
            .fold(0.0, f64::max)
            .max(1e-300);
        let roll_front = section_roll(mesh, asm, &shape, front);
        let roll_rear = section_roll(mesh, asm, &shape, rear);
        let twist = if roll_front * roll_rear < 0.0 {
            (roll_front - roll_rear).abs() * half_width / amplitude
        } else {
            0.0
        };
        // Vertical bending signature: front end and rear move together against the middle.
        let mean_uz = |nodes: &[usize]| {
            nodes
                .iter()
                .map(|&i| translation(asm, &shape, i).z)
                .sum::<f64>()
                / nodes.len().max(1) as f64
        };
        let (front_uz, rear_uz, mid_uz) =
            (mean_uz(front_end_nodes), mean_uz(rear), mean_uz(&mid_sill));
        let bending = if front_uz * rear_uz > 0.0 && mid_uz * front_uz < 0.0 {
            (mid_uz.abs() + front_uz.abs().min(rear_uz.abs())) / amplitude
        } else {
            0.0
        };
        let elastic = elastic_fraction(mesh, asm, &shape, body);
        let wheel_share = |d: usize| match asm.dofs.global(wheel, d) {
            Some(g) if total > 0.0 => shape[g] * m_phi[g] / total,
            _ => 0.0,
        };
        let (wheel_vertical, wheel_lateral) = (wheel_share(2), wheel_share(1));
        let steering = energy.get(region::STEERING).copied().unwrap_or(0.0);
        let front_end = energy.get(region::FRONT_END).copied().unwrap_or(0.0);
        let kind = if elastic < 0.05 {
            ModeKind::RigidBody(rigid_label(mesh, asm, &shape, body))
        } else if steering > 0.5 {
            if wheel_vertical + wheel_lateral < 0.05 {
                ModeKind::SteeringColumn
            } else if wheel_vertical >= wheel_lateral {
                ModeKind::SteeringWheelVertical
            } else {
                ModeKind::SteeringWheelLateral
            }
        } else if twist > 0.5 && front_end < 0.5 {
            ModeKind::GlobalTorsion
        } else if bending > 0.25 {
            ModeKind::GlobalBending
        } else if front_end > 0.3 {
            ModeKind::FrontEnd
        } else {
            // The region holding the largest energy fraction, other than the whole body.
            let local = energy
                .iter()
                .filter(|(name, _)| name.as_str() != region::BODY)
                .map(|(name, e)| (name, *e))
                .max_by(|a, b| a.1.total_cmp(&b.1))
                .map(|(name, _)| name.clone())
                .unwrap_or_default();
            ModeKind::Local(local)
        };
        out.push(ModeDescription {
            index: k,
            frequency_hz,
            kind,
            energy,
            twist,
            bending,
            elastic,
            wheel_vertical,
            wheel_lateral,
        });
    }
    // The main wheel pair is labelled by relative direction (see `steering_wheel_pair`).
    if let Some((v, l)) = steering_wheel_pair(&out) {
        out[v].kind = ModeKind::SteeringWheelVertical;
        out[l].kind = ModeKind::SteeringWheelLateral;
    }
    Ok(out)
}
