//! Eigensolvers for the sparse symmetric pencil (K, M) of a structure.
//!
//! - [`lowest_modes`] ([`shift_invert`]): shift-invert block Lanczos at one shift, with full
//!   M-reorthogonalisation and locking; the solver for tens of modes.
//! - [`slicing`]: spectrum slicing over several shifts, each slice's completeness proved by Sturm
//!   counts; the solver for hundreds of modes or bodies of a million DOFs.
//!   [`slicing::lowest_modes_auto`] and [`slicing::modes_in_interval`] pick between the two.
//! - [`block_product`]: a sparse matrix times a dense block, one pass over the matrix per eight
//!   columns; the kernel of the solvers' and the Craig-Bampton reduction's projections.
//!
//! They know nothing of cars: the pencil comes from [`crate::fe::assembly`] (or any other
//! assembly in the same [`crate::fe::assembly::SparseMat`] form).

pub mod block_product;
pub mod shift_invert;
pub mod slicing;

pub use shift_invert::{check_pencil, lowest_modes, Modes};
