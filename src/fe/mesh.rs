//! The mesh: nodes, elements, lumped masses, springs, constraints, named nodes and regions.

use std::collections::BTreeMap;

use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

pub use super::section::{Material, ShellSection};

/// Degrees of freedom per node (three translations, three rotations).
pub const DOF_PER_NODE: usize = 6;

/// Beam cross-section. `iy` resists bending in the local x-z plane, `iz` in the local x-y plane.
///
/// The shear area factors give the transverse shear stiffness k·A·G of each plane (Timoshenko,
/// see [`crate::fe::beam`]); `None` is rigid in shear, the Euler-Bernoulli beam of that plane
/// (what the procedural body's beams and a PBAR without K1/K2 are).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BeamSection {
    /// Area (m²).
    pub area: f64,
    /// Second moment about the local y axis (m⁴).
    pub iy: f64,
    /// Second moment about the local z axis (m⁴).
    pub iz: f64,
    /// Saint-Venant torsion constant (m⁴).
    pub j: f64,
    /// Shear area factor of the local x-y plane (shear force along y, bending with `iz`;
    /// Nastran's K1, plane 1): shear stiffness `shear_factor_y`·A·G. `None`: rigid in shear.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_factor_y: Option<f64>,
    /// Shear area factor of the local x-z plane (shear force along z, bending with `iy`;
    /// Nastran's K2, plane 2). `None`: rigid in shear.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub shear_factor_z: Option<f64>,
}

impl BeamSection {
    /// Thin-walled rectangular tube, outer width `b` (local y), height `h` (local z), wall `t`.
    pub fn box_tube(b: f64, h: f64, t: f64) -> Self {
        let (bi, hi) = (b - 2.0 * t, h - 2.0 * t);
        let area = b * h - bi.max(0.0) * hi.max(0.0);
        let iy = (b * h.powi(3) - bi * hi.powi(3)) / 12.0;
        let iz = (h * b.powi(3) - hi * bi.powi(3)) / 12.0;
        // Bredt: J = 4 A_m² t / perimeter of the wall mid-line.
        let (bm, hm) = (b - t, h - t);
        let j = 4.0 * (bm * hm).powi(2) * t / (2.0 * (bm + hm));
        Self::rigid_in_shear(area, iy, iz, j)
    }

    /// Thin-walled circular tube, outer diameter `d`, wall `t`.
    pub fn circular_tube(d: f64, t: f64) -> Self {
        let di = (d - 2.0 * t).max(0.0);
        let area = std::f64::consts::PI / 4.0 * (d * d - di * di);
        let i = std::f64::consts::PI / 64.0 * (d.powi(4) - di.powi(4));
        Self::rigid_in_shear(area, i, i, 2.0 * i)
    }

    /// Section with area, second moments and torsion constant, rigid in transverse shear
    /// (Euler-Bernoulli in both planes).
    pub fn rigid_in_shear(area: f64, iy: f64, iz: f64, j: f64) -> Self {
        Self {
            area,
            iy,
            iz,
            j,
            shear_factor_y: None,
            shear_factor_z: None,
        }
    }
}

/// Two-node 3D Euler-Bernoulli beam (12 DOF).
#[derive(Debug, Clone, PartialEq)]
pub struct Beam {
    /// End nodes.
    pub nodes: [usize; 2],
    /// Material.
    pub material: Material,
    /// Section properties.
    pub section: BeamSection,
    /// Any vector not parallel to the beam axis; the local y axis lies in its plane with the axis.
    pub orientation: Vector3<f64>,
    /// Non-structural mass per length (kg/m) (trim carried by the beam).
    pub extra_mass_per_length: f64,
}

/// End conditions of a [`Beam`] that Nastran's CBAR/CBEAM carry: rigid offsets from the nodes
/// to the element ends and pin flags releasing element DOFs at an end.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BeamEnds {
    /// Vector from each node to its element end in global axes (m): the end sits at
    /// node + offset and is carried rigidly by the node (u_end = u + θ × offset, θ_end = θ).
    pub offsets: [Vector3<f64>; 2],
    /// Released DOFs per end in element axes (x along the beam, y and z of the section; order
    /// ux uy uz rx ry rz): the element transmits no force or moment there.
    pub pins: [[bool; 6]; 2],
}

/// Four-node flat shell (membrane with drilling rotation + MITC4 plate).
#[derive(Debug, Clone, PartialEq)]
pub struct Shell {
    /// Corner nodes, counter-clockwise seen from the side the normal points to.
    pub nodes: [usize; 4],
    /// Material.
    pub material: Material,
    /// Thickness (m) (membrane stiffness and mass).
    pub thickness: f64,
    /// Effective thickness for plate bending and transverse shear (m): equal to `thickness` for a
    /// plain sheet, larger for a beaded or stiffened panel in a phenomenological model.
    pub bending_thickness: f64,
    /// Non-structural mass per area (kg/m²) (trim carried by the panel).
    pub extra_mass_per_area: f64,
    /// General section (anisotropic materials, separate bending and shear materials, offset);
    /// when given it replaces `material`'s E and ν and the thicknesses in the stiffness, while
    /// the mass still follows density, thickness and bending thickness. `None`: the plain
    /// isotropic sheet.
    pub section: Option<Box<ShellSection>>,
}

/// Three-node flat shell (CST membrane with drilling rotation + DKT plate, lumped mass); the
/// fields mean what they mean for [`Shell`].
#[derive(Debug, Clone, PartialEq)]
pub struct TriShell {
    /// Corner nodes, counter-clockwise seen from the side the normal points to.
    pub nodes: [usize; 3],
    /// Material.
    pub material: Material,
    /// Thickness (m) (membrane stiffness and mass).
    pub thickness: f64,
    /// Effective thickness for plate bending (m).
    pub bending_thickness: f64,
    /// Non-structural mass per area (kg/m²).
    pub extra_mass_per_area: f64,
    /// General section, as for [`Shell`] (the triangle has no transverse shear flexibility,
    /// so the section's shear matrix is not used).
    pub section: Option<Box<ShellSection>>,
}

/// Solid element (Nastran CTETRA, CPENTA, CHEXA) with translational stiffness and consistent
/// mass only; the formulation follows the node count (see [`crate::fe::solid`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Solid {
    /// Nodes in Nastran order: 4 or 10 (tetrahedron), 6 (wedge), 8 (hexahedron).
    pub nodes: Vec<usize>,
    /// Material.
    pub material: Material,
}

/// Point mass with rotary inertia (global axes) at a node.
#[derive(Debug, Clone, PartialEq)]
pub struct PointMass {
    /// Node carrying the mass.
    pub node: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Rotary inertia tensor about the node in global axes (kg m²) (symmetric).
    pub inertia: Matrix3<f64>,
}

/// Spring-damper from a node to ground, uncoupled per global DOF.
#[derive(Debug, Clone, PartialEq)]
pub struct GroundSpring {
    /// Node.
    pub node: usize,
    /// Stiffness per DOF ux, uy, uz (N/m), rx, ry, rz (N m/rad).
    pub stiffness: [f64; 6],
    /// Viscous damping per DOF (N s/m), (N m s/rad).
    pub damping: [f64; 6],
}

/// Spring-damper between two nodes acting on the relative displacement per global DOF.
#[derive(Debug, Clone, PartialEq)]
pub struct Spring {
    /// The two nodes.
    pub nodes: [usize; 2],
    /// Stiffness per DOF (N/m), (N m/rad).
    pub stiffness: [f64; 6],
    /// Viscous damping per DOF (N s/m), (N m s/rad).
    pub damping: [f64; 6],
}

/// Generalised spring-damper (Nastran CBUSH): six uncoupled stiffnesses and dampers along the
/// axes of its own frame, acting on the relative motion of a point carried rigidly by both ends
/// (by end `a` alone and ground for a bush to ground).
#[derive(Debug, Clone, PartialEq)]
pub struct Bush {
    /// First end.
    pub a: usize,
    /// Second end; `None`: the bush connects `a` to ground.
    pub b: Option<usize>,
    /// Element axes in global coordinates (columns x, y, z; orthonormal).
    pub frame: Matrix3<f64>,
    /// Global position of the spring point (the lever arms run from each end to it).
    pub point: Vector3<f64>,
    /// Stiffness along/about the element axes x, y, z (N/m), then rx, ry, rz (N m/rad).
    pub stiffness: [f64; 6],
    /// Viscous damping along/about the element axes (N s/m), (N m s/rad).
    pub damping: [f64; 6],
}

/// Rigid element (Nastran RBE2): the listed components of every dependent node follow the
/// small-displacement rigid-body motion of the independent node,
/// u_d = u_i + θ_i × (x_d − x_i), θ_d = θ_i. Eliminated exactly in assembly.
#[derive(Debug, Clone, PartialEq)]
pub struct RigidLink {
    /// Node whose six DOFs drive the link.
    pub independent: usize,
    /// Nodes that follow it.
    pub dependent: Vec<usize>,
    /// Which local DOFs (ux uy uz rx ry rz) of the dependent nodes are tied.
    pub components: [bool; 6],
}

/// One group of source nodes of an [`InterpolationLink`] with a common weight.
#[derive(Debug, Clone, PartialEq)]
pub struct InterpolationSource {
    /// Nodes of the group.
    pub nodes: Vec<usize>,
    /// Weight (> 0) of the group.
    pub weight: f64,
    /// Which local DOFs of these nodes take part in the average.
    pub components: [bool; 6],
}

/// Interpolation element (Nastran RBE3): the reference node moves with the rigid-body motion
/// that best fits, in the weighted least-squares sense, the motion of the source nodes. Adds no
/// stiffness; eliminated exactly in assembly. See [`crate::fe::links`] for the weighting.
#[derive(Debug, Clone, PartialEq)]
pub struct InterpolationLink {
    /// The dependent reference node.
    pub reference: usize,
    /// Which local DOFs of the reference node are dependent.
    pub reference_components: [bool; 6],
    /// Weighted source node groups.
    pub sources: Vec<InterpolationSource>,
}

/// A complete FE model description before assembly.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Mesh {
    /// Node coordinates (m); the index is the node id.
    pub nodes: Vec<Vector3<f64>>,
    /// Beam elements.
    pub beams: Vec<Beam>,
    /// Offsets and pin flags of beams, by index into `beams` (a beam not listed has neither).
    pub beam_ends: BTreeMap<usize, BeamEnds>,
    /// Displacement frames of nodes (Nastran GRID CD), by node: the columns are the frame's
    /// axes in global coordinates (orthonormal, right-handed). The six DOFs of such a node are
    /// its components in this frame: constraints, scalar springs and dampers and rigid link
    /// components name them; elements and masses are given in global axes and transformed, and
    /// motions recovered from a [`super::dof::DofMap`] are global. Nodes not listed are global.
    pub displacement_frames: BTreeMap<usize, Matrix3<f64>>,
    /// Shell elements.
    pub shells: Vec<Shell>,
    /// Three-node shell elements.
    pub triangles: Vec<TriShell>,
    /// Solid elements.
    pub solids: Vec<Solid>,
    /// Point masses.
    pub masses: Vec<PointMass>,
    /// Springs to ground.
    pub ground_springs: Vec<GroundSpring>,
    /// Two-node springs.
    pub springs: Vec<Spring>,
    /// Spring-dampers in their own axes (CBUSH).
    pub bushes: Vec<Bush>,
    /// Fixed DOFs `(node, local dof 0..5)`.
    pub constraints: Vec<(usize, usize)>,
    /// Rigid elements (dependent DOFs eliminated in assembly).
    pub rigid_links: Vec<RigidLink>,
    /// Interpolation elements (dependent reference DOFs eliminated in assembly).
    pub interpolation_links: Vec<InterpolationLink>,
    /// Named special nodes (engine mounts, steering wheel, seat rail, wheel centres …).
    pub named_nodes: BTreeMap<String, usize>,
    /// Named node sets used to describe mode shapes (steering column, front end …).
    pub regions: BTreeMap<String, Vec<usize>>,
}

impl Mesh {
    /// Adds a node and returns its id.
    pub fn add_node(&mut self, p: Vector3<f64>) -> usize {
        self.nodes.push(p);
        self.nodes.len() - 1
    }

    /// Positions of an element's corner `nodes`, each checked as by [`Mesh::position`].
    pub fn positions<const N: usize>(
        &self,
        what: &str,
        nodes: &[usize; N],
    ) -> Result<[Vector3<f64>; N], super::FeError> {
        let mut points = [Vector3::zeros(); N];
        for (point, &node) in points.iter_mut().zip(nodes) {
            *point = self.position(what, node)?;
        }
        Ok(points)
    }

    /// Position of `node`, which `what` (an element, a link) refers to: an error if the node
    /// does not exist or its coordinates are not finite.
    pub fn position(&self, what: &str, node: usize) -> Result<Vector3<f64>, super::FeError> {
        let p = self.nodes.get(node).copied().ok_or_else(|| {
            super::FeError::Mesh(format!(
                "{what} refers to node {node}, mesh has {} nodes",
                self.nodes.len()
            ))
        })?;
        if p.iter().any(|c| !c.is_finite()) {
            return Err(super::FeError::Mesh(format!(
                "{what}: node {node} has non-finite coordinates"
            )));
        }
        Ok(p)
    }

    /// Id of a named node.
    pub fn named(&self, name: &str) -> Option<usize> {
        self.named_nodes.get(name).copied()
    }

    /// Clamps all six DOFs of `node`.
    pub fn clamp(&mut self, node: usize) {
        self.constraints.extend((0..6).map(|d| (node, d)));
    }
}
