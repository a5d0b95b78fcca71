//! Component mode synthesis of the chassis: Craig-Bampton reduction with constraint-mode
//! orthogonalisation (paper §3.2, eq. 14–15), modal damping, and the recovery of named points.
//!
//! The product is a [`ReducedChassis`]: every coordinate is a mode with a frequency, the reduced
//! mass matrix is the identity and the stiffness diagonal, so the chassis enters the coupled model
//! as `η̈_k + 2 ζ_k ω_k η̇_k + ω_k² η_k = Σ_p φ_{p,k} · F_p`, with `F_p` the force (and moment)
//! acting on recovery point `p` and `φ_{p,k}` that point's 6-DOF motion in mode `k`.
//!
//! The body is one of three ([`BodySource`]): the procedural chassis ([`crate::chassis`]), a
//! bulk data deck ([`crate::nastran`]), or Craig-Bampton matrices reduced elsewhere (DMIG).
//!
//! Pipeline: [`ReductionSpec`] → [`reduce`] (builds and assembles the body, interface = the
//! translational, or all six, DOFs of the layout's mount nodes) → [`craig_bampton()`] (constraint
//! modes by sparse Cholesky, fixed-interface modes by [`crate::eigen`]'s shift-invert Lanczos, with
//! spectrum slicing for many modes or large bodies ([`crate::eigen::slicing`]),
//! orthogonalisation) → [`ReducedChassis`] with the rows of the recovery points only.
//! [`reduce_cached`] keeps the result in the user's cache directory.
//!
//! A body reduced in another solver comes as Craig-Bampton matrices (Nastran `DMIG`,
//! [`BodySource::Dmig`]): [`reduce_external`] takes it from there the same way
//! ([`orthogonalise`], the damping table), and [`dmig_of_reduction`] writes our own reduction
//! in that form.
//!
//! Only the rows of named points are kept; [`recover_all_nodes`] recovers the simulated modes on
//! every node when a tool asks (operating deflection shapes), outside any instance.
//!
//! Recovery points, in order: the layout's mount nodes (`mount_front_left`, `mount_front_right`,
//! `mount_rear_left`, `mount_rear_right`, minus the one the three-mount layout removes), then the
//! spec's `outputs` (default `steering_wheel`, `seat_rail`; any named FE node is allowed).
//!
//! Damping: modal, per [`DampingTable`]; with [`ReductionSpec::discrete_dampers`] the FE model's
//! suspension dampers are added as `φ_kᵀ C φ_k / (2 ω_k)` (about 21–28 % in the rigid-body modes
//! on the suspension, within 7 % of a full damped solve in `tests/cms/damping.rs`).
//!
//! Mode selection ([`ModeSelection`]) applies to the fixed-interface modes; all constraint modes
//! are always kept, so the reduced chassis has `n_fixed + 3 × mounts` (or `6 ×`) modes, the
//! highest of them stiff interface modes (kHz) that the ADAMS table damps critically. Rule of
//! thumb from `tests/cms_*.rs`: keep fixed-interface modes up to 3× the highest frequency of
//! interest (frequencies within 0.2 %, transfer functions within 1 % up to a ninth of the
//! cut-off and 10 % up to a third).
//!
//! ```no_run
//! use engine_mount_chassis::cms::{
//!     reduce_cached, CacheSetting, ModeSelection, PointDof, ReductionSpec, Response,
//! };
//! # fn main() -> Result<(), engine_mount_chassis::cms::CmsError> {
//! let spec = ReductionSpec {
//!     selection: ModeSelection::CutoffHz(450.0),
//!     ..ReductionSpec::default()
//! };
//! let (chassis, _outcome) = reduce_cached(&spec, &CacheSetting::Default)?;
//! let wheel = chassis.point("steering_wheel").expect("recovered by default");
//! println!("{} modes, wheel uz in mode 0: {}", chassis.n_modes(), wheel.shape[0][2]);
//! let h = chassis.transfer_function(
//!     PointDof { point: "mount_front_left", dof: 2 },
//!     PointDof { point: "steering_wheel", dof: 2 },
//!     Response::Acceleration,
//!     &[30.0, 31.5, 33.0],
//! )?;
//! # let _ = h;
//! # Ok(())
//! # }
//! ```

mod cache;
mod craig_bampton;
mod damping;
mod dmig_export;
mod error;
mod external;
mod hash;
mod recovery;
mod reduce;
mod reduced;
mod sparse_ops;
mod spec;
mod transfer;

pub use cache::{
    reduce_cached, reduce_cached_with_notes, CacheOutcome, CacheSetting, FORMAT_VERSION,
};
pub use craig_bampton::{
    craig_bampton, craig_bampton_basis, orthogonalise, CraigBampton, CraigBamptonBasis,
};
pub use damping::{
    BodyDamping, DampingTable, DampingUnit, OwnDamping, TableError, DEFAULT_BODY_DAMPING_RATIO,
};
pub use dmig_export::{dmig_of_reduction, DmigBody};
pub use error::CmsError;
pub use external::{reduce_external, ExternalBody};
pub use hash::sha256_hex;
pub use recovery::{recover_all_nodes, FullRecovery};
pub use reduce::{reduce, reduce_detailed, reduce_with_notes, Reduction};
pub use reduced::{RecoveryPoint, ReducedChassis};
pub use sparse_ops::Partition;
pub use spec::{
    BodySource, BulkDeckBody, DmigBodySource, InterfaceDofs, ModeSelection, ReductionSpec,
};
pub use transfer::{PointDof, Response};
