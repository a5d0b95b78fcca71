//! Finite elements, sparse assembly and the procedural chassis body (paper §5).
//!
//! Frame: ISO 8855 vehicle axes (x forward, y left, z up), origin at the front-axle centre on the
//! ground; the rear axle is at x = −2.54 m. SI units throughout. Six DOFs per node: ux, uy, uz,
//! rx, ry, rz in global axes.
//!
//! Pipeline: [`chassis_config::ChassisConfig`] (JSON, serde defaults) →
//! [`chassis::Chassis::build`] ([`mesh::Mesh`] with named nodes and regions, checked by
//! [`checks::check_mesh`]) → [`assembly::assemble`] (faer `SparseColMat` K, M, C and a
//! [`dof::DofMap`]) → [`eigen::lowest_modes`] (sparse Cholesky + shift-invert block Lanczos) →
//! [`modal::describe`] (torsion, bending, steering wheel, front end …); [`export`] writes K, M
//! (Matrix Market) and the node/DOF tables. Hundreds of modes: [`eigen_slicing`] (spectrum
//! slicing over several shifts, completeness by Sturm counts);
//! [`block_product`] multiplies a sparse matrix by many vectors in one pass per eight of them.
//!
//! ```no_run
//! use engine_mount_chassis::fe::{assembly, chassis, chassis_config, eigen, modal};
//! # fn main() -> Result<(), engine_mount_chassis::fe::FeError> {
//! let body = chassis::Chassis::build(&chassis_config::ChassisConfig::default())?;
//! let asm = assembly::assemble(&body.mesh)?;
//! let mounts = body.mount_nodes(chassis::MountLayout::Four)?; // [(name, node id)]
//! let row = asm.dofs.global(mounts[0].1, 2); // equation index of the first mount's uz
//! let modes = eigen::lowest_modes(&asm.k, &asm.m, 30, -1.0)?;
//! for d in modal::describe(&body.mesh, &asm, &modes)? {
//!     println!("{}", d.summary());
//! }
//! # let _ = row;
//! # Ok(())
//! # }
//! ```
//!
//! Rigid and interpolation links (RBE2/RBE3, [`links`]) are eliminated exactly in assembly.
//! [`nastran`] reads and writes Nastran bulk data.
//!
//! Elements: [`beam`] (Euler-Bernoulli, 12 DOF, HRZ-lumped mass), [`shell`] (QM6 membrane
//! with Hughes–Brezzi drilling rotation + MITC4 plate, lumped mass), [`shell3`] (CST membrane +
//! DKT plate), [`solid`] (tetrahedra, wedge, hexahedron; consistent mass), [`mass`] (point mass with
//! rotary inertia), [`spring`] (grounded and two-node spring-dampers).

pub mod assembly;
pub mod beam;
pub mod block_product;
pub mod chassis;
pub mod chassis_config;
pub mod checks;
pub mod dof;
pub mod eigen;
pub mod eigen_slicing;
pub mod error;
pub mod export;
pub mod links;
pub mod mass;
pub mod mesh;
pub mod modal;
pub mod nastran;
pub mod nodal_frames;
pub mod shell;
pub mod shell3;
pub mod solid;
pub mod spring;
#[cfg(test)]
mod test_support;

pub use error::FeError;
