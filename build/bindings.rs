//! The bindings generated from the variable table: each unit's factor to SI once, and each
//! variable the runtime reads or writes bound to it by its row:
//! - a Real output to its accessor of the runtime's outputs (the row's `"output"`, e.g.
//!   `"mount_force[i][j]"`, with `i`, `j` the family's indices from 0), an Integer output to its
//!   accessor of the integrator's counters (`"output": "steps"`);
//! - a Real input to the runtime input it is (the row's `"input"`, a variant of
//!   `crate::model::Input`, e.g. `"StiffnessScale(i)"`), with its unit's factor to SI, both
//!   ways: from the variable to the input (to build the runtime's inputs) and back (to name the
//!   variable in a refusal);
//! - the interface inputs: those an output's `feedthrough` names.
//!
//! A new output is its row with its accessor and the model function that fills the accessor; a
//! new input is its row with its `Input` and the model function that uses it; nothing else names
//! them.

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

/// The table's variables with their families (`expand` makes one family per row, in order).
fn rows<'a>(
    table: &'a Value,
    families: &'a [super::Family],
) -> impl Iterator<Item = (&'a Value, &'a super::Family)> {
    let variables = table
        .get("variables")
        .and_then(Value::as_array)
        .unwrap_or_else(|| super::fail("`variables` must be an array"));
    if variables.len() != families.len() {
        super::fail("the families do not match the table's rows");
    }
    variables.iter().zip(families)
}

/// Every binding: `put_outputs`, `put_counters`, `input_of`, `input_variable` and
/// `is_interface_input`.
pub fn rust_bindings(table: &Value, families: &[super::Family]) -> String {
    real_outputs(table, families)
        + &integer_outputs(table, families)
        + &inputs(table, families)
        + &interface_inputs(families)
}

/// Whether an accessor or input pattern names the indices `[i]`, `[j]` (or `(i, j)`) exactly as
/// the family's dims have them; the build fails otherwise.
fn check_indices(name: &str, binding: &str, indices: &[&str], dims: usize) {
    let named: Vec<bool> = ["i", "j"]
        .iter()
        .map(|index| indices.contains(index))
        .collect();
    if named[0] != (dims >= 1) || named[1] != (dims >= 2) || indices.len() != dims {
        super::fail(&format!(
            "the binding {binding:?} of {name} must use the indices i (and j) as its dims do"
        ));
    }
}

/// The indices an accessor uses: `[i]` and `[j]`.
fn accessor_indices(accessor: &str) -> Vec<&str> {
    ["i", "j"]
        .into_iter()
        .filter(|index| accessor.contains(&format!("[{index}]")))
        .collect()
}

/// `put_outputs`: every Real output of the table written from its accessor of
/// `crate::cosim::Outputs`. A Real output without an accessor fails the build.
fn real_outputs(table: &Value, families: &[super::Family]) -> String {
    let mut body = String::new();
    for (v, f) in rows(table, families) {
        if super::str_field(v, "causality") != "output" || f.ty != "Real" {
            continue;
        }
        let (rust, name) = (&f.rust, &f.name);
        let accessor = v.get("output").and_then(Value::as_str).unwrap_or_else(|| {
            super::fail(&format!(
                "Real output {name} has no \"output\": the accessor of cosim::Outputs it is read from"
            ))
        });
        check_indices(name, accessor, &accessor_indices(accessor), f.dims.len());
        let _ = writeln!(body, "    // {name}");
        let _ = match f.dims.len() {
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

/// `put_counters`: every Integer output of the table written from its accessor of
/// `crate::cosim::Counters`, saturated to the Integer's range. An Integer output without an
/// accessor, or an array of them, fails the build.
fn integer_outputs(table: &Value, families: &[super::Family]) -> String {
    let mut body = String::new();
    for (v, f) in rows(table, families) {
        if super::str_field(v, "causality") != "output" || f.ty != "Integer" {
            continue;
        }
        let (rust, name) = (&f.rust, &f.name);
        let accessor = v.get("output").and_then(Value::as_str).unwrap_or_else(|| {
            super::fail(&format!(
                "Integer output {name} has no \"output\": the accessor of cosim::Counters it is \
                 read from"
            ))
        });
        if !f.dims.is_empty() {
            super::fail(&format!("Integer output {name}: only scalars are bound"));
        }
        check_indices(name, accessor, &accessor_indices(accessor), 0);
        let _ = writeln!(
            body,
            "    // {name}\n    n.put(integer::{rust}, saturated(c.{accessor}));"
        );
    }
    format!(
        "\n/// Writes the integrator's counters into the Integers: each Integer output of the \
         variable table\n/// from its accessor.\n\
         pub fn put_counters(n: &mut Store<i32>, c: &Counters) {{\n{body}}}\n"
    )
}

/// A Real input's binding: the `Input` variant its row names and its arguments (`i`, `j`).
fn input_pattern<'a>(name: &str, pattern: &'a str, dims: usize) -> (&'a str, Vec<&'a str>) {
    let (variant, arguments) = match pattern.split_once('(') {
        None => (pattern, Vec::new()),
        Some((variant, rest)) => {
            let inner = rest.strip_suffix(')').unwrap_or_else(|| {
                super::fail(&format!("the input {pattern:?} of {name} lacks its `)`"))
            });
            (variant, inner.split(',').map(str::trim).collect())
        }
    };
    let is_identifier = |s: &str| {
        s.chars().next().is_some_and(|c| c.is_ascii_uppercase())
            && s.chars().all(|c| c.is_ascii_alphanumeric())
    };
    if !is_identifier(variant)
        || arguments
            .iter()
            .enumerate()
            .any(|(k, a)| *a != ["i", "j"][k.min(1)])
    {
        super::fail(&format!(
            "the input {pattern:?} of {name} must be a variant of model::Input with the \
             arguments i (and j), as `StiffnessScale(i)`"
        ));
    }
    check_indices(name, pattern, &arguments, dims);
    (variant, arguments)
}

/// `input_of` and `input_variable`: every Real input of the table bound to the runtime input
/// its row names, with the factor of its unit to SI (`units`), both ways. A Real input without
/// an `"input"` fails the build; an `Input` no row names fails the compilation (the match of
/// `input_variable` is exhaustive), as does one named twice (an unreachable arm).
fn inputs(table: &Value, families: &[super::Family]) -> String {
    let mut forward = String::new();
    let mut back = String::new();
    for (v, f) in rows(table, families) {
        if super::str_field(v, "causality") != "input" {
            continue;
        }
        let (rust, name) = (&f.rust, &f.name);
        if f.ty != "Real" {
            super::fail(&format!("input {name}: only Real inputs are bound"));
        }
        let pattern = v.get("input").and_then(Value::as_str).unwrap_or_else(|| {
            super::fail(&format!(
                "Real input {name} has no \"input\": the model::Input it binds to"
            ))
        });
        let (variant, arguments) = input_pattern(name, pattern, f.dims.len());
        let input = if arguments.is_empty() {
            format!("Input::{variant}")
        } else {
            format!("Input::{variant}({})", arguments.join(", "))
        };
        let (to_si, from_si) = match &f.unit {
            Some(unit) => {
                let constant = format!("units::{}", unit_constant(unit));
                (constant.clone(), format!("1.0 / {constant}"))
            }
            None => ("1.0".to_owned(), "1.0".to_owned()),
        };
        let count: usize = f.dims.iter().product();
        let (first, last) = (f.first_vr, f.first_vr + count - 1);
        let _ = match f.dims.as_slice() {
            [] => writeln!(
                forward,
                "        // {name}\n        {first} => Some(({input}, {to_si})),"
            ),
            [_] => writeln!(
                forward,
                "        // {name}\n        {first}..={last} => {{\n            \
                 let i = (index - {first}) as usize;\n            \
                 Some(({input}, {to_si}))\n        }}"
            ),
            [_, m] => writeln!(
                forward,
                "        // {name}\n        {first}..={last} => {{\n            \
                 let (i, j) = ((index - {first}) as usize / {m}, (index - {first}) as usize % {m});\n            \
                 Some(({input}, {to_si}))\n        }}"
            ),
            _ => unreachable!(),
        };
        let _ = match f.dims.len() {
            0 => writeln!(back, "        {input} => Some((real::{rust}, {from_si})),"),
            1 => writeln!(
                back,
                "        {input} => real::{rust}.get(i).map(|&k| (k, {from_si})),"
            ),
            _ => writeln!(
                back,
                "        {input} => real::{rust}\n            .get(i)\n            \
                 .and_then(|m| m.get(j))\n            .map(|&k| (k, {from_si})),"
            ),
        };
    }
    format!(
        "\n/// The runtime input the Real at `index` is (its row's `\"input\"`) and the factor from \
         its unit to SI;\n/// `None` for a Real that is not an input.\n\
         pub fn input_of(index: u32) -> Option<(Input, f64)> {{\n    match index {{\n{forward}        \
         _ => None,\n    }}\n}}\n\n\
         /// The Real input behind a runtime input and the factor from SI to the input's unit \
         (`None` for a\n/// mount the FMU's variables do not have): the way back of [`input_of`].\n\
         pub fn input_variable(input: Input) -> Option<(u32, f64)> {{\n    match input {{\n{back}    }}\n}}\n"
    )
}

/// `is_interface_input`: the Real inputs some output responds to at once (named in a row's
/// `feedthrough`).
fn interface_inputs(families: &[super::Family]) -> String {
    let mut spans: Vec<(usize, usize)> = families
        .iter()
        .filter(|f| families.iter().any(|g| g.feedthrough.contains(&f.rust)))
        .map(|f| {
            (
                f.first_vr,
                f.first_vr + f.dims.iter().product::<usize>() - 1,
            )
        })
        .collect();
    spans.sort_unstable();
    // Adjacent families make one range (as clippy wants the pattern written).
    let mut merged: Vec<(usize, usize)> = Vec::new();
    for (first, last) in spans {
        match merged.last_mut() {
            Some(previous) if previous.1 + 1 >= first => previous.1 = previous.1.max(last),
            _ => merged.push((first, last)),
        }
    }
    let ranges: Vec<String> = merged
        .iter()
        .map(|(first, last)| format!("{first}..={last}"))
        .collect();
    let test = if ranges.is_empty() {
        "{ let _ = index; false }".to_owned()
    } else {
        format!("matches!(index, {})", ranges.join(" | "))
    };
    format!(
        "\n/// Whether the Real at `index` is an input through which outputs respond at once (an \
         output's\n/// `feedthrough` in the table: the interface to an external body).\n\
         pub fn is_interface_input(index: u32) -> bool {{\n    {test}\n}}\n"
    )
}
