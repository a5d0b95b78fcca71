//! A user's body from a Nastran bulk data deck (free field and small field).
//!
//! Supported: `GRID` (in the basic system or a `CORD2R`; permanent constraints), `CORD2R`,
//! `CQUAD4` with `PSHELL` (membrane and bending thickness via 12I/T³, non-structural mass),
//! `CBAR`/`CBEAM` with `PBAR`/`PBEAM` (constant section, orientation vector or G0), `MAT1`,
//! `CONM2` (at its grid, with rotary inertia), `CELAS1`/`PELAS`, `CELAS2`, `CDAMP2` (to ground or
//! between like components of two grids), `SPC1` (with `THRU`); `PARAM`, `EIGRL`, `EIGR` are
//! accepted and ignored. Everything else — `CTRIA3`, `RBE2`, `RBE3`, offsets, pin flags,
//! large-field cards, other cards — is an error naming the card and its line: nothing is silently
//! dropped. Mount and output points are grids, named by their GRID id in the vehicle
//! configuration.
//!
//! [`write_bulk_deck`] writes a [`Mesh`] of these elements back (free field, full precision).

mod lexer;
mod model;
mod writer;

use std::path::Path;

pub use lexer::{cards, parse_real, Card};
pub use model::NastranBody;
pub use writer::write_bulk_deck;

use crate::fe::FeError;

/// Parses a bulk data deck given as text.
pub fn parse_str(text: &str) -> Result<NastranBody, FeError> {
    model::build(&cards(text)?)
}

/// Reads a bulk data deck (a regular file of at most [`crate::text_file::DATA_LIMIT`] bytes).
pub fn read_bulk_deck(path: &Path) -> Result<NastranBody, FeError> {
    let text =
        crate::text_file::read_limited(path, crate::text_file::DATA_LIMIT).map_err(FeError::Io)?;
    parse_str(&text).map_err(|e| match e {
        FeError::InvalidInput(m) => FeError::InvalidInput(format!("{}: {m}", path.display())),
        other => other,
    })
}
