//! Modal damping: TABDMP1.

use super::fields::Reader;
use crate::fe::error::FeError;
use crate::nastran::lexer::{Loc, Value};

/// A `TABDMP1` as read: modal damping against natural frequency, its values in the card's unit
/// (the reduction turns the table the case control's `SDAMPING` names into the body's damping).
#[derive(Debug, Clone, PartialEq)]
pub struct DampingTableCard {
    /// Table id (TID).
    pub id: u32,
    /// TYPE: `G` (blank, Nastran's default), `CRIT` or `Q`.
    pub kind: &'static str,
    /// (frequency in cycles per unit time, value) pairs in the order given, `SKIP` pairs left
    /// out.
    pub points: Vec<[f64; 2]>,
    /// Where each point's frequency field is, for messages.
    pub point_lines: Vec<Loc>,
    /// Where the card starts.
    pub loc: Loc,
}

/// `TABDMP1 TID TYPE` (fields 4–9 blank, or OptiStruct's `FLAT = 1` in field 4), then pairs
/// `f1 g1 f2 g2 …` on the continuations up to `ENDT`; a pair with `SKIP` in either field is
/// left out. Outside the table the end values are held (`FLAT = 1`); the linear extrapolation
/// of MSC Nastran (`FLAT = 0` in OptiStruct) is refused when asked for explicitly.
pub(crate) fn tabdmp1(r: &Reader) -> Result<DampingTableCard, FeError> {
    let id = r.id(0, "TID")?;
    let kind = match r.value(1, "TYPE")? {
        Value::Blank => "G",
        Value::Text(t) if t == "G" => "G",
        Value::Text(t) if t == "CRIT" => "CRIT",
        Value::Text(t) if t == "Q" => "Q",
        other => {
            return Err(r.error(
                1,
                "TYPE",
                format!(
                    "TABDMP1 {id}: damping type '{}' is not handled (G, CRIT or Q)",
                    shown(&other)
                ),
            ));
        }
    };
    match r.opt_int(2, "FLAT")? {
        None | Some(1) => {}
        Some(0) => {
            return Err(r.error(
                2,
                "FLAT",
                format!(
                    "TABDMP1 {id}: FLAT = 0 (linear extrapolation beyond the table) is not \
                     handled: the end values are held (FLAT = 1)"
                ),
            ))
        }
        Some(v) => return Err(r.error(2, "FLAT", format!("must be 0 or 1, got {v}"))),
    }
    for i in 3..8 {
        if !matches!(r.value(i, "blank")?, Value::Blank) {
            return Err(r.error(i, "blank", format!("TABDMP1 {id}: the field must be blank")));
        }
    }
    let (points, point_lines) = table_points(r, id)?;
    Ok(DampingTableCard {
        id,
        kind,
        points,
        point_lines,
        loc: r.card().loc(),
    })
}

/// A field's value as the deck shows it, for messages.
fn shown(value: &Value) -> String {
    match value {
        Value::Text(t) => t.clone(),
        Value::Int(v) => v.to_string(),
        Value::Real(v) => v.to_string(),
        Value::Blank => String::new(),
    }
}

/// The pairs `f1 g1 f2 g2 …` of a `TABDMP1` from its field 9 up to `ENDT`, with the place of each
/// point's frequency; a pair with `SKIP` in either field left out.
fn table_points(r: &Reader, id: u32) -> Result<(Vec<[f64; 2]>, Vec<Loc>), FeError> {
    let is = |v: &Value, word: &str| matches!(v, Value::Text(t) if t == word);
    let (mut points, mut point_lines) = (Vec::new(), Vec::new());
    let mut i = 8;
    loop {
        let (f, g) = (r.value(i, "fi")?, r.value(i + 1, "gi")?);
        // A frequency whose value field holds ENDT: the table ends with a point half given.
        if is(&g, "ENDT") && !matches!(f, Value::Blank) && !is(&f, "SKIP") {
            return Err(r.error(
                i,
                "fi",
                format!(
                    "TABDMP1 {id}: the frequency {} has no damping value before ENDT (each \
                     point is a frequency and its value)",
                    shown(&f)
                ),
            ));
        }
        if is(&f, "ENDT") || is(&g, "ENDT") {
            let after = if is(&f, "ENDT") { i + 1 } else { i + 2 };
            return match (after..r.len())
                .find(|&j| !matches!(r.value(j, "").ok(), Some(Value::Blank)))
            {
                Some(j) => Err(r.error(
                    j,
                    "after ENDT",
                    format!("TABDMP1 {id}: data after the end of the table (ENDT)"),
                )),
                None if points.is_empty() => Err(r.card_error(format!(
                    "TABDMP1 {id}: the table has no point (at least one frequency and value \
                     before ENDT)"
                ))),
                None => Ok((points, point_lines)),
            };
        }
        if i >= r.len() {
            return Err(r.card_error(format!("TABDMP1 {id}: no ENDT ends the table")));
        }
        if !(is(&f, "SKIP") || is(&g, "SKIP")) {
            points.push([r.real(i, "fi")?, r.real(i + 1, "gi")?]);
            point_lines.push(r.field_loc(i));
        }
        i += 2;
    }
}
