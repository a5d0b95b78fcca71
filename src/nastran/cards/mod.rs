//! Typed bulk data cards, one file per family: each supported card's fields read by position
//! with Nastran's types and defaults ([`fields::Reader`]), every malformed field an error naming
//! the line, field number and meaning; and [`Cards`], a deck's cards as read, by kind. Which
//! card is read by which function, and stored where, is the table
//! [`super::card_table::CARD_TABLE`]; what the cards become is [`super::to_mesh`].

mod beam;
mod bush;
mod damping;
mod fields;
mod grid;
mod link;
mod mass;
mod material;
mod scalar;
mod shell;
mod solid;
mod spc;

use std::collections::BTreeMap;

pub(crate) use beam::{bar, pbar, pbeam, Bar, BeamProperty, Orientation, VectorSystem};
pub(crate) use bush::{cbush, pbush, BushAxes, Cbush, Pbush};
pub(crate) use damping::tabdmp1;
pub use damping::DampingTableCard;
pub(crate) use fields::Reader;
pub(crate) use grid::{cord2, grid, Cord2r, Grid, SystemKind};
pub(crate) use link::{rbe2, rbe3, Rbe2, Rbe3};
pub(crate) use mass::{conm1, conm2, Conm1, Conm2};
pub(crate) use material::{mat1, mat2, mat8, Mat1, ShellMaterialCard};
pub(crate) use scalar::{scalar, scalar_properties, Scalar, ScalarValue};
pub(crate) use shell::{plate, pshell, Plate, Pshell};
pub(crate) use solid::{element as solid_element, psolid, Psolid, SolidElement};
pub(crate) use spc::{spc, spc1, Grids, Support};

use super::lexer::{Loc, Value};
use crate::fe::error::FeError;

/// The cards of a deck as read, by kind (ids unique per kind; element ids unique over all
/// element cards).
#[derive(Default)]
pub(crate) struct Cards {
    pub(crate) grids: BTreeMap<u32, Grid>,
    pub(crate) systems: BTreeMap<u32, Cord2r>,
    pub(crate) materials: BTreeMap<u32, Mat1>,
    pub(crate) shell_materials: BTreeMap<u32, ShellMaterialCard>,
    pub(crate) shell_properties: BTreeMap<u32, Pshell>,
    pub(crate) beam_properties: BTreeMap<u32, (BeamProperty, &'static str)>,
    pub(crate) spring_properties: BTreeMap<u32, (f64, Loc)>,
    pub(crate) damper_properties: BTreeMap<u32, (f64, Loc)>,
    pub(crate) bars: BTreeMap<u32, Bar>,
    pub(crate) plates: BTreeMap<u32, (Plate, &'static str)>,
    pub(crate) masses: BTreeMap<u32, Conm2>,
    pub(crate) general_masses: BTreeMap<u32, Conm1>,
    pub(crate) bush_properties: BTreeMap<u32, Pbush>,
    pub(crate) bushes: BTreeMap<u32, Cbush>,
    pub(crate) springs: BTreeMap<u32, Scalar>,
    pub(crate) dampers: BTreeMap<u32, Scalar>,
    pub(crate) rigid: BTreeMap<u32, Rbe2>,
    pub(crate) interpolation: BTreeMap<u32, Rbe3>,
    pub(crate) solids: BTreeMap<u32, SolidElement>,
    pub(crate) solid_properties: BTreeMap<u32, Psolid>,
    pub(crate) supports: Vec<(Support, Loc)>,
    pub(crate) damping_tables: BTreeMap<u32, DampingTableCard>,
    /// Element id → where its card is and which card it is.
    pub(crate) element_lines: BTreeMap<u32, (Loc, &'static str)>,
    /// PARAM WTMASS (1 without).
    pub(crate) mass_scale: f64,
}

/// A message about the card at `line`.
pub(crate) fn deck_error(line: impl std::fmt::Display, message: impl std::fmt::Display) -> FeError {
    FeError::InvalidInput(format!("Nastran bulk data line {line}: {message}"))
}

/// Stores `value` under `id`, refusing a second card of `what` with that id.
pub(crate) fn insert_unique<T>(
    map: &mut BTreeMap<u32, T>,
    what: &str,
    id: u32,
    line: &Loc,
    value: T,
) -> Result<(), FeError> {
    if map.insert(id, value).is_some() {
        return Err(deck_error(line, format!("{what} {id} is defined twice")));
    }
    Ok(())
}

/// Stores element `value` of card `name` under `id` in `map`, refusing an id another element
/// card already has (element ids are unique over all element cards, as in Nastran).
pub(crate) fn insert_element<T>(
    element_lines: &mut BTreeMap<u32, (Loc, &'static str)>,
    map: &mut BTreeMap<u32, T>,
    name: &'static str,
    id: u32,
    line: &Loc,
    value: T,
) -> Result<(), FeError> {
    if let Some((first, other)) = element_lines.get(&id) {
        return Err(deck_error(
            line,
            format!("{name} {id}: element id already used by {other} at line {first}"),
        ));
    }
    element_lines.insert(id, (line.clone(), name));
    map.insert(id, value);
    Ok(())
}

impl Cards {
    /// No cards, no WTMASS.
    pub(crate) fn new() -> Self {
        Cards {
            mass_scale: 1.0,
            ..Cards::default()
        }
    }

    /// PARAM: WTMASS scales every mass; the output-only parameters of `ignored` are accepted;
    /// any other is refused (it may change K or M).
    pub(crate) fn param(&mut self, r: &Reader, ignored: &[&str]) -> Result<(), FeError> {
        let name = match r.value(0, "N")? {
            Value::Text(t) => t,
            other => return Err(r.error(0, "N", format!("expected a name, found {other:?}"))),
        };
        if name == "WTMASS" {
            let w = r.real(1, "V1")?;
            if !(w.is_finite() && w > 0.0) {
                return Err(r.error(1, "V1", format!("WTMASS must be > 0, got {w}")));
            }
            self.mass_scale = w;
            Ok(())
        } else if ignored.contains(&name.as_str()) {
            Ok(())
        } else {
            Err(r.card_error(format!(
                "PARAM {name} is not supported (it may change K or M); supported: WTMASS, and \
                 ignored as output-only: {}",
                ignored.join(", ")
            )))
        }
    }
}
