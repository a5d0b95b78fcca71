//! Typed access to the fields of one card: each field read by position with Nastran's types
//! and defaults; every malformed field is an error naming the line, field number and meaning.

use crate::fe::error::FeError;
use crate::nastran::lexer::{classify, Loc, RawCard, Value};

/// Typed access to the fields of one card.
pub(crate) struct Reader<'a> {
    card: &'a RawCard,
}

impl<'a> Reader<'a> {
    pub(crate) fn new(card: &'a RawCard) -> Self {
        Self { card }
    }

    pub(crate) fn card(&self) -> &RawCard {
        self.card
    }

    /// Where data field `i` is (or would be): line and Nastran field number.
    fn place(&self, i: usize) -> (Loc, usize) {
        match self.card.fields.get(i) {
            Some(f) => (self.card.loc_of_line(f.line), f.position),
            None => (self.card.loc(), i % 8 + 2),
        }
    }

    /// Where data field `i` is (its line).
    pub(crate) fn field_loc(&self, i: usize) -> Loc {
        self.place(i).0
    }

    pub(crate) fn error(&self, i: usize, name: &str, message: impl std::fmt::Display) -> FeError {
        let (line, position) = self.place(i);
        FeError::InvalidInput(format!(
            "Nastran bulk data line {line}: {} (card at line {}) field {position} ({name}): \
             {message}",
            self.card.name,
            self.card.loc()
        ))
    }

    /// A whole-card error at the card's first line.
    pub(crate) fn card_error(&self, message: impl std::fmt::Display) -> FeError {
        FeError::InvalidInput(format!(
            "Nastran bulk data line {}: {}: {message}",
            self.card.loc(),
            self.card.name
        ))
    }

    pub(crate) fn len(&self) -> usize {
        self.card.fields.len()
    }

    pub(crate) fn value(&self, i: usize, name: &str) -> Result<Value, FeError> {
        match self.card.fields.get(i) {
            None => Ok(Value::Blank),
            Some(f) => classify(&f.text).map_err(|m| self.error(i, name, m)),
        }
    }

    pub(crate) fn opt_int(&self, i: usize, name: &str) -> Result<Option<i64>, FeError> {
        match self.value(i, name)? {
            Value::Blank => Ok(None),
            Value::Int(v) => Ok(Some(v)),
            other => Err(self.error(i, name, format!("expected an integer, found {other:?}"))),
        }
    }

    pub(crate) fn int_or(&self, i: usize, name: &str, default: i64) -> Result<i64, FeError> {
        Ok(self.opt_int(i, name)?.unwrap_or(default))
    }

    /// A positive identification number (required).
    pub(crate) fn id(&self, i: usize, name: &str) -> Result<u32, FeError> {
        match self.opt_id(i, name)? {
            Some(v) => Ok(v),
            None => Err(self.error(i, name, "is required")),
        }
    }

    /// A positive identification number or blank.
    pub(crate) fn opt_id(&self, i: usize, name: &str) -> Result<Option<u32>, FeError> {
        match self.opt_int(i, name)? {
            None => Ok(None),
            Some(v) if v > 0 && v <= u32::MAX as i64 => Ok(Some(v as u32)),
            Some(v) => Err(self.error(i, name, format!("must be a positive id, got {v}"))),
        }
    }

    /// An id where blank and 0 both mean "none" (coordinate systems, optional grids).
    pub(crate) fn opt_id_or_zero(&self, i: usize, name: &str) -> Result<Option<u32>, FeError> {
        match self.opt_int(i, name)? {
            None | Some(0) => Ok(None),
            Some(v) if v > 0 && v <= u32::MAX as i64 => Ok(Some(v as u32)),
            Some(v) => Err(self.error(i, name, format!("must be >= 0, got {v}"))),
        }
    }

    pub(crate) fn opt_real(&self, i: usize, name: &str) -> Result<Option<f64>, FeError> {
        match self.value(i, name)? {
            Value::Blank => Ok(None),
            Value::Real(v) => Ok(Some(v)),
            Value::Int(v) => Err(self.error(
                i,
                name,
                format!("expected a real, found integer {v} (Nastran reals need a decimal point)"),
            )),
            other => Err(self.error(i, name, format!("expected a real, found {other:?}"))),
        }
    }

    pub(crate) fn real(&self, i: usize, name: &str) -> Result<f64, FeError> {
        self.opt_real(i, name)?
            .ok_or_else(|| self.error(i, name, "is required"))
    }

    pub(crate) fn real_or(&self, i: usize, name: &str, default: f64) -> Result<f64, FeError> {
        Ok(self.opt_real(i, name)?.unwrap_or(default))
    }

    /// Component digits 1..6 ("123456", no repeats) as a DOF mask (required, non-empty).
    pub(crate) fn components(&self, i: usize, name: &str) -> Result<[bool; 6], FeError> {
        let Some(v) = self.opt_int(i, name)? else {
            return Err(self.error(i, name, "component digits 1..6 are required"));
        };
        let text = v.to_string();
        let mut mask = [false; 6];
        for c in text.chars() {
            match c.to_digit(10) {
                Some(d @ 1..=6) if !mask[d as usize - 1] => mask[d as usize - 1] = true,
                _ => {
                    return Err(self.error(
                        i,
                        name,
                        format!("'{text}' is not a set of distinct component digits 1..6"),
                    ))
                }
            }
        }
        Ok(mask)
    }

    /// A single scalar-element component 1..6 (0/blank would be a scalar point: not supported).
    pub(crate) fn component(&self, i: usize, name: &str) -> Result<usize, FeError> {
        match self.opt_int(i, name)? {
            Some(c @ 1..=6) => Ok(c as usize - 1),
            other => Err(self.error(
                i,
                name,
                format!(
                    "expected one component 1..6, found {other:?} (scalar points are not supported)"
                ),
            )),
        }
    }

    /// Field `i` must be blank (or a zero of either type): features this reader does not model.
    pub(crate) fn require_blank(&self, i: usize, name: &str, why: &str) -> Result<(), FeError> {
        match self.value(i, name)? {
            Value::Blank => Ok(()),
            Value::Int(0) | Value::Real(0.0) => Ok(()),
            other => Err(self.error(i, name, format!("{other:?} is not supported: {why}"))),
        }
    }

    /// No data beyond field index `n - 1`.
    pub(crate) fn at_most(&self, n: usize) -> Result<(), FeError> {
        match self
            .card
            .fields
            .iter()
            .enumerate()
            .skip(n)
            .find(|(_, f)| !f.text.is_empty())
        {
            Some((i, f)) => Err(self.error(
                i,
                "beyond the card's last field",
                format!("unexpected data '{}'", f.text),
            )),
            None => Ok(()),
        }
    }
}
