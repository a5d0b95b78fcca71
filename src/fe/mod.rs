//! General finite elements and sparse assembly: what any body is made of, whoever describes it
//! (the procedural chassis in [`crate::chassis`], a Nastran deck in [`crate::nastran`]).
//!
//! Frame: ISO 8855 vehicle axes (x forward, y left, z up), origin at the front-axle centre on the
//! ground. SI units throughout. Six DOFs per node: ux, uy, uz, rx, ry, rz in global axes, or in
//! a node's own displacement frame ([`nodal_frames`]).
//!
//! Pipeline: a [`mesh::Mesh`] (nodes, elements, masses, springs, links, supports), checked by
//! [`checks::check_mesh`] → [`assembly::assemble`] (faer `SparseColMat` K, M, C and a
//! [`dof::DofMap`]) → the eigensolvers of [`crate::eigen`]; [`export`] writes K, M (Matrix
//! Market) and the node/DOF tables.
//!
//! Rigid and interpolation links (RBE2/RBE3, [`links`]) are eliminated exactly in assembly.
//!
//! Every kind of mesh entity implements one trait, [`element::Element`] (its nodes, matrices or
//! constraint equations, shape checks and bulk data cards), in its own file, and is listed once
//! in the registry [`elements`]; assembly, the checks and the deck writer loop over the
//! registry. Kinds: [`beam`] (Timoshenko or Euler-Bernoulli, 12 DOF, HRZ-lumped mass),
//! [`shell`] (QM6 membrane with Hughes–Brezzi drilling rotation + MITC4 plate, lumped mass),
//! [`shell3`] (CST membrane + DKT plate), [`solid`] (tetrahedra, wedge, hexahedron; consistent
//! mass), [`mass`] (point mass with rotary inertia), [`ground_spring`] and [`spring`]
//! (spring-dampers to ground and between two nodes), [`bush`] (spring-dampers in their own
//! axes), [`rigid_link`] and [`interpolation_link`]; [`section`] holds the materials and general
//! shell sections they use.

pub mod assembly;
pub mod beam;
pub mod bush;
pub mod checks;
pub mod dof;
pub mod element;
pub mod elements;
pub mod error;
pub mod export;
pub mod ground_spring;
pub mod interpolation_link;
pub mod links;
pub mod mass;
pub mod mesh;
pub mod nodal_frames;
pub mod rigid_link;
pub mod section;
pub mod shell;
pub mod shell3;
pub mod solid;
pub mod spring;
#[cfg(test)]
mod test_support;

pub use error::FeError;
