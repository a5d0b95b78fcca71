//! The bindings generated from the variable table: each unit's factor to SI once, and each Real
//! output variable bound to its accessor of the runtime's outputs (the row's `"output"`, e.g.
//! `"mount_force[i][j]"`, with `i`, `j` the family's indices from 0). A new output is its row
//! with its accessor and the model function that fills the accessor; nothing else names it.

use serde_json::Value;
use std::fmt::Write as _;

/// The Rust name of a unit's constant: `rpm` → `RPM`, `rad/s` → `RAD_PER_S`, `N.m` → `N_M`.
fn unit_constant(name: &str) -> String {
    name.replace('/', "_per_")
        .replace(['.', ' ', '-'], "_")
        .to_uppercase()
}

/// `pub mod units`: per unit of the table, the factor from the unit to SI (its `factor`, 1 for
/// an SI unit), for the variables' values and the runtime's conversions.
pub fn rust_units(table: &Value) -> String {
    let units = table
        .get("units")
        .and_then(Value::as_array)
        .unwrap_or_else(|| super::fail("`units` must be an array"));
    let mut out = String::from(
        "/// Per unit of the variable table, the factor from a value in that unit to SI: the one \
         definition of each\n/// unit conversion (`modelDescription/variables.json`).\npub mod units {\n",
    );
    for u in units {
        let name = super::str_field(u, "name");
        let factor = u.get("factor").and_then(Value::as_f64).unwrap_or(1.0);
        let _ = writeln!(
            out,
            "    /// `{name}` → SI.\n    pub const {}: f64 = {factor:?};",
            unit_constant(name)
        );
    }
    out + "}\n"
}

/// `put_outputs`: every Real output of the table written from its accessor of
/// `crate::cosim::Outputs`. A Real output without an accessor fails the build.
pub fn rust_bindings(table: &Value) -> String {
    let variables = table
        .get("variables")
        .and_then(Value::as_array)
        .unwrap_or_else(|| super::fail("`variables` must be an array"));
    let mut body = String::new();
    for v in variables {
        if super::str_field(v, "causality") != "output" || super::str_field(v, "type") != "Real" {
            continue;
        }
        let rust = super::str_field(v, "rust");
        let name = super::str_field(v, "name");
        let accessor = v.get("output").and_then(Value::as_str).unwrap_or_else(|| {
            super::fail(&format!(
                "Real output {name} has no \"output\": the accessor of cosim::Outputs it is read from"
            ))
        });
        let dims = v.get("dims").and_then(Value::as_array).map_or(0, Vec::len);
        let uses = |index: &str| accessor.contains(&format!("[{index}]"));
        if uses("i") != (dims >= 1) || uses("j") != (dims >= 2) {
            super::fail(&format!(
                "the accessor {accessor:?} of {name} must index [i] (and [j]) as its dims do"
            ));
        }
        let _ = writeln!(body, "    // {name}");
        let _ = match dims {
            0 => writeln!(body, "    r.put(real::{rust}, o.{accessor});"),
            1 => writeln!(
                body,
                "    for (i, &slot) in real::{rust}.iter().enumerate() {{\n        \
                 r.put(slot, o.{accessor});\n    }}"
            ),
            _ => writeln!(
                body,
                "    for (i, row) in real::{rust}.iter().enumerate() {{\n        \
                 for (j, &slot) in row.iter().enumerate() {{\n            \
                 r.put(slot, o.{accessor});\n        }}\n    }}"
            ),
        };
    }
    format!(
        "/// Writes the runtime's outputs into the Reals: each Real output of the variable table \
         from its accessor\n/// (both FMUs' outputs: each FMU lists its own).\n\
         pub fn put_outputs(r: &mut Store<f64>, o: &Outputs) {{\n{body}}}\n"
    )
}
