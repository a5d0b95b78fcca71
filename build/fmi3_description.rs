//! The FMI 3.0 side of `build.rs`, from the same variable table as the 2.0 files:
//! - `fmi3/modelDescription.xml`: a family with `dims` becomes one array variable (`mount[{i}].F[{j}]`
//!   becomes `mount.F` with dimensions 4 × 3), the natural modes become arrays whose length is the
//!   structural parameter `modes.size`; units, display units and descriptions as in 2.0;
//! - `fmi3/terminalsAndIcons.xml`: terminals grouping the engine inputs and the outputs;
//! - the Rust map from each 3.0 value reference to the scalar indices of the 2.0 table (appended
//!   to `variables.rs`);
//! - [`FMI3_FUNCTIONS`], the exported fmi3 symbols.
//!
//! Value references: a 3.0 variable takes the 2.0 value reference of its first element, so a
//! scalar keeps its 2.0 value reference and arrays never overlap; `time` and `modes.size`, which
//! have no 2.0 counterpart, sit above the 2.0 ranges.

use super::{attr, element, fail, opt_str, str_field, value_text, vr_base, Family, Fmu, VR_BASE};
use quick_xml::events::{BytesDecl, Event};
use quick_xml::Writer;
use serde_json::Value;
use std::fmt::Write as _;

/// Every function of `fmi3Functions.h`: the common and co-simulation API, and the model-exchange
/// and scheduled-execution functions, which refuse (masters such as fmpy resolve them all).
pub const FMI3_FUNCTIONS: [&str; 75] = [
    "fmi3GetVersion",
    "fmi3SetDebugLogging",
    "fmi3InstantiateModelExchange",
    "fmi3InstantiateCoSimulation",
    "fmi3InstantiateScheduledExecution",
    "fmi3FreeInstance",
    "fmi3EnterInitializationMode",
    "fmi3ExitInitializationMode",
    "fmi3EnterEventMode",
    "fmi3Terminate",
    "fmi3Reset",
    "fmi3GetFloat32",
    "fmi3GetFloat64",
    "fmi3GetInt8",
    "fmi3GetUInt8",
    "fmi3GetInt16",
    "fmi3GetUInt16",
    "fmi3GetInt32",
    "fmi3GetUInt32",
    "fmi3GetInt64",
    "fmi3GetUInt64",
    "fmi3GetBoolean",
    "fmi3GetString",
    "fmi3GetBinary",
    "fmi3GetClock",
    "fmi3SetFloat32",
    "fmi3SetFloat64",
    "fmi3SetInt8",
    "fmi3SetUInt8",
    "fmi3SetInt16",
    "fmi3SetUInt16",
    "fmi3SetInt32",
    "fmi3SetUInt32",
    "fmi3SetInt64",
    "fmi3SetUInt64",
    "fmi3SetBoolean",
    "fmi3SetString",
    "fmi3SetBinary",
    "fmi3SetClock",
    "fmi3GetNumberOfVariableDependencies",
    "fmi3GetVariableDependencies",
    "fmi3GetFMUState",
    "fmi3SetFMUState",
    "fmi3FreeFMUState",
    "fmi3SerializedFMUStateSize",
    "fmi3SerializeFMUState",
    "fmi3DeserializeFMUState",
    "fmi3GetDirectionalDerivative",
    "fmi3GetAdjointDerivative",
    "fmi3EnterConfigurationMode",
    "fmi3ExitConfigurationMode",
    "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction",
    "fmi3GetShiftDecimal",
    "fmi3GetShiftFraction",
    "fmi3SetIntervalDecimal",
    "fmi3SetIntervalFraction",
    "fmi3SetShiftDecimal",
    "fmi3SetShiftFraction",
    "fmi3EvaluateDiscreteStates",
    "fmi3UpdateDiscreteStates",
    "fmi3EnterStepMode",
    "fmi3GetOutputDerivatives",
    "fmi3DoStep",
    "fmi3EnterContinuousTimeMode",
    "fmi3CompletedIntegratorStep",
    "fmi3SetTime",
    "fmi3SetContinuousStates",
    "fmi3GetContinuousStateDerivatives",
    "fmi3GetEventIndicators",
    "fmi3GetContinuousStates",
    "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfEventIndicators",
    "fmi3GetNumberOfContinuousStates",
    "fmi3ActivateModelPartition",
];

/// Value reference of the independent variable `time`.
const TIME_VR: usize = 4000;
/// Value reference of the structural parameter `modes.size`.
const MODES_SIZE_VR: usize = 4001;

/// One 3.0 variable: a table entry with its 2.0 family.
struct Var3<'a> {
    entry: &'a Value,
    family: &'a Family,
    name: String,
    vr: usize,
    /// The length of the first dimension is `modes.size` (the natural modes).
    sized_by_modes: bool,
}

fn type3(ty: &str) -> &'static str {
    match ty {
        "Real" => "Float64",
        "Integer" => "Int32",
        "Boolean" => "Boolean",
        _ => "String",
    }
}

/// The 3.0 variables of the table's entries, in table order.
fn variables<'a>(table: &'a Value, families: &'a [Family], mask: u8) -> Vec<Var3<'a>> {
    let entries = table
        .get("variables")
        .and_then(Value::as_array)
        .unwrap_or_else(|| fail("`variables` must be an array"));
    let mut names = std::collections::BTreeSet::new();
    // Each 3.0 FMU is its 2.0 twin: the variables tagged for it (untagged: the engine's).
    let in_fmu = |entry: &Value| {
        let tagged = |name: &str| {
            entry
                .get("fmus")
                .and_then(Value::as_array)
                .is_some_and(|l| l.iter().any(|f| f.as_str() == Some(name)))
        };
        let untagged = entry.get("fmus").is_none();
        (mask & super::ENGINE != 0 && (untagged || tagged("engine")))
            || (mask & super::BODY != 0 && tagged("body"))
    };
    let vars: Vec<Var3> = entries
        .iter()
        .zip(families)
        .filter(|(entry, _)| in_fmu(entry))
        .map(|(entry, family)| {
            let name = family.name.replace("[{i}]", "").replace("[{j}]", "");
            if name.contains('{') {
                fail(&format!(
                    "{}: array indices must be `[{{i}}]`/`[{{j}}]`",
                    family.name
                ));
            }
            if !names.insert(name.clone()) {
                fail(&format!("FMI 3.0 name {name} occurs twice"));
            }
            let sized_by_modes =
                family.dims.len() == 1 && str_field(entry, "causality") == "calculatedParameter";
            Var3 {
                entry,
                family,
                name,
                vr: family.first_vr + vr_base(family.ty),
                sized_by_modes,
            }
        })
        .collect();
    let sizes: Vec<usize> = vars
        .iter()
        .filter(|v| v.sized_by_modes)
        .map(|v| v.family.dims[0])
        .collect();
    if sizes.windows(2).any(|w| w[0] != w[1]) {
        fail("the natural-mode arrays must have one length");
    }
    vars
}

/// The longest natural-mode array (the 2.0 table's slots), the maximum of `modes.size`.
fn modes_max(vars: &[Var3]) -> usize {
    vars.iter()
        .find(|v| v.sized_by_modes)
        .map(|v| v.family.dims[0])
        .unwrap_or_else(|| fail("no natural-mode array (calculatedParameter with dims)"))
}

/// The description of an array: the family's, with its placeholders named. A 3.0 description
/// must not speak of FMI 2.0's functions (the table's descriptions serve both standards).
fn description3(v: &Var3) -> String {
    let text = v.family.description.replace("{i}", "i").replace("{j}", "j");
    if text.contains("fmi2") {
        fail(&format!(
            "{}: the description names an FMI 2.0 function; say what it does for both standards",
            v.family.name
        ));
    }
    match v.family.dims.len() {
        0 => text,
        1 => format!("{text}. Array element [i]"),
        _ => format!("{text}. Array element [i, j]"),
    }
}

/// Writes, below `out/fmi3`, each FMU's `modelDescription.xml` and `terminalsAndIcons.xml`
/// (the body FMU's prefixed `body.`, as the 2.0 files).
pub fn write_files(out: &std::path::Path, table: &Value, families: &[Family], fmus: &[Fmu]) {
    let dir = out.join("fmi3");
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| fail(&format!("cannot create {}: {e}", dir.display())));
    for fmu in fmus {
        let prefix = if fmu.mask == super::BODY { "body." } else { "" };
        let vars = variables(table, families, fmu.mask);
        let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
        write_model_description(&mut w, table, &vars, fmu)
            .unwrap_or_else(|e| fail(&format!("writing the FMI 3.0 modelDescription.xml: {e}")));
        super::write(
            &dir.join(format!("{prefix}modelDescription.xml")),
            &finish(w),
        );
        let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
        write_terminals(&mut w, &vars, fmu.mask)
            .unwrap_or_else(|e| fail(&format!("writing terminalsAndIcons.xml: {e}")));
        super::write(
            &dir.join(format!("{prefix}terminalsAndIcons.xml")),
            &finish(w),
        );
    }
}

fn finish(w: Writer<Vec<u8>>) -> String {
    let mut xml = String::from_utf8(w.into_inner()).expect("quick-xml writes UTF-8");
    xml.push('\n');
    xml
}

fn write_model_description(
    w: &mut Writer<Vec<u8>>,
    table: &Value,
    vars: &[Var3],
    fmu: &Fmu,
) -> std::io::Result<()> {
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let root = vec![
        attr("fmiVersion", "3.0"),
        attr("modelName", fmu.model_name),
        attr("instantiationToken", &fmu.guid),
        attr("description", fmu.description),
        attr("author", str_field(table, "author")),
        attr("version", str_field(table, "version")),
        attr("generationTool", "engine_mount_chassis build.rs"),
        attr("variableNamingConvention", "structured"),
    ];
    element(w, "fmiModelDescription", &root).write_inner_content(|w| {
        // No event mode, no intermediate update, no early return: fmi3DoStep always completes
        // the step (or stops at a failure, reported by fmi3Discard).
        let co_simulation = vec![
            attr("modelIdentifier", fmu.identifier),
            attr("needsExecutionTool", false),
            attr("canBeInstantiatedOnlyOncePerProcess", false),
            attr("canGetAndSetFMUState", true),
            attr("canSerializeFMUState", true),
            // fmi3GetDirectionalDerivative: outputs with respect to the interface inputs.
            attr("providesDirectionalDerivatives", true),
            attr("providesAdjointDerivatives", false),
            attr("providesPerElementDependencies", false),
            attr("canHandleVariableCommunicationStepSize", true),
            // fmi3GetOutputDerivatives: the engine's outputs (the body alone has none).
            attr(
                "maxOutputDerivativeOrder",
                u8::from(fmu.mask == super::ENGINE),
            ),
            attr("providesIntermediateUpdate", false),
            attr("mightReturnEarlyFromDoStep", false),
            attr("canReturnEarlyAfterIntermediateUpdate", false),
            attr("hasEventMode", false),
            attr("providesEvaluateDiscreteStates", false),
        ];
        element(w, "CoSimulation", &co_simulation).write_empty()?;
        super::write_units_categories_experiment(w, table, &|w| write_types(w, vars))?;
        let max = modes_max(vars);
        w.create_element("ModelVariables")
            .write_inner_content(|w| {
                let time = vec![
                    attr("name", "time"),
                    attr("valueReference", TIME_VR),
                    attr("causality", "independent"),
                    attr("variability", "continuous"),
                    attr("description", "Simulation time"),
                    attr("declaredType", type_name("s", None)),
                ];
                element(w, "Float64", &time).write_empty()?;
                let mut sized_written = false;
                for v in vars {
                    if v.sized_by_modes && !sized_written {
                        sized_written = true;
                        let size = vec![
                            attr("name", "modes.size"),
                            attr("valueReference", MODES_SIZE_VR),
                            attr("causality", "structuralParameter"),
                            attr("variability", "fixed"),
                            attr(
                                "description",
                                format!(
                                    "Length of the natural-mode arrays mode.*: the lowest modes.size \
                                     natural modes are reported (1..{max}; entries beyond modes.count \
                                     are 0). Set in configuration mode"
                                ),
                            ),
                            attr("start", max),
                            attr("min", 1),
                            attr("max", max),
                        ];
                        element(w, "UInt64", &size).write_empty()?;
                    }
                    write_variable(w, v)?;
                }
                Ok(())
            })?;
        let knowns: Vec<String> = vars
            .iter()
            .filter(|v| matches!(str_field(v.entry, "causality"), "parameter" | "input"))
            .map(|v| v.vr)
            .chain(std::iter::once(MODES_SIZE_VR))
            .map(|vr| vr.to_string())
            .collect();
        let knowns = knowns.join(" ");
        w.create_element("ModelStructure")
            .write_inner_content(|w| {
                // As in the 2.0 file: outputs come from the state at the communication point, so
                // none depends directly on an input except through the external body's interface
                // (the table's `feedthrough`; arrays depend on whole arrays); at the end of
                // initialisation every output and calculated parameter depends on every input and
                // parameter.
                for v in vars
                    .iter()
                    .filter(|v| str_field(v.entry, "causality") == "output")
                {
                    let direct: Vec<String> = vars
                        .iter()
                        .filter(|k| v.family.feedthrough.contains(&k.family.rust))
                        .map(|k| k.vr.to_string())
                        .collect();
                    let unknown = vec![
                        attr("valueReference", v.vr),
                        attr("dependencies", direct.join(" ")),
                    ];
                    element(w, "Output", &unknown).write_empty()?;
                }
                for v in vars.iter().filter(|v| {
                    matches!(
                        str_field(v.entry, "causality"),
                        "output" | "calculatedParameter"
                    )
                }) {
                    let unknown = vec![
                        attr("valueReference", v.vr),
                        attr("dependencies", &knowns),
                    ];
                    element(w, "InitialUnknown", &unknown).write_empty()?;
                }
                Ok(())
            })?;
        Ok(())
    })?;
    Ok(())
}

/// The name of the Float64 type of `unit` shown in `display`: the variables carry their unit and
/// display unit through a declared type, as the Reference-FMUs do.
fn type_name(unit: &str, display: Option<&str>) -> String {
    match display {
        Some(d) if d != unit => format!("{unit} [{d}]"),
        _ => unit.to_owned(),
    }
}

/// `<TypeDefinitions>`: one Float64 type per unit and display unit the variables (and `time`)
/// use.
fn write_types(w: &mut Writer<Vec<u8>>, vars: &[Var3]) -> std::io::Result<()> {
    let mut types = std::collections::BTreeMap::new();
    types.insert(type_name("s", None), ("s".to_owned(), None));
    for v in vars {
        if let Some(u) = opt_str(v.entry, "unit") {
            let display = opt_str(v.entry, "displayUnit");
            types.insert(type_name(&u, display.as_deref()), (u, display));
        }
    }
    w.create_element("TypeDefinitions")
        .write_inner_content(|w| {
            for (name, (unit, display)) in &types {
                let mut a = vec![attr("name", name), attr("unit", unit)];
                if let Some(d) = display {
                    a.push(attr("displayUnit", d));
                }
                element(w, "Float64Type", &a).write_empty()?;
            }
            Ok(())
        })?;
    Ok(())
}

fn write_variable(w: &mut Writer<Vec<u8>>, v: &Var3) -> std::io::Result<()> {
    let e = v.entry;
    let ty = v.family.ty;
    let mut a = vec![
        attr("name", &v.name),
        attr("valueReference", v.vr),
        attr("causality", str_field(e, "causality")),
        attr("variability", str_field(e, "variability")),
        attr("description", description3(v)),
    ];
    // A String's start values are <Start> elements (FMI 3.0 §2.4.7.4), the others' a list.
    let count = v.family.dims.iter().product::<usize>().max(1);
    let mut string_starts = Vec::new();
    if let Some(start) = e.get("start") {
        let one = value_text(start);
        if ty == "String" {
            string_starts = vec![one; count];
        } else {
            a.push(attr("start", vec![one; count].join(" ")));
        }
    }
    if let Some(u) = opt_str(e, "unit") {
        if ty != "Real" {
            fail(&format!(
                "{}: only Float64 variables have units in FMI 3.0",
                v.name
            ));
        }
        let display = opt_str(e, "displayUnit");
        a.push(attr("declaredType", type_name(&u, display.as_deref())));
    }
    if matches!(ty, "Real" | "Integer") {
        for key in ["min", "max"] {
            if let Some(m) = e.get(key).and_then(Value::as_f64) {
                a.push(attr(key, super::number_text(ty, m)));
            }
        }
    }
    let tag = type3(ty);
    if v.family.dims.is_empty() && string_starts.is_empty() {
        return element(w, tag, &a).write_empty().map(|_| ());
    }
    element(w, tag, &a).write_inner_content(|w| {
        if v.sized_by_modes {
            element(w, "Dimension", &vec![attr("valueReference", MODES_SIZE_VR)]).write_empty()?;
        } else {
            for d in &v.family.dims {
                element(w, "Dimension", &vec![attr("start", d)]).write_empty()?;
            }
        }
        for value in &string_starts {
            element(w, "Start", &vec![attr("value", value)]).write_empty()?;
        }
        Ok(())
    })?;
    Ok(())
}

/// A terminal: its name, description and members as (variable, memberName).
type Terminal<'a> = (&'a str, &'a str, &'a [(&'a str, &'a str)]);

/// Terminals: the engine's inputs, the mounts' port to the body (the external body's motion
/// in, the mount forces out), the scales of the mount characteristics, the powertrain's motion
/// and the comfort points.
fn write_terminals(w: &mut Writer<Vec<u8>>, vars: &[Var3], mask: u8) -> std::io::Result<()> {
    // (variable, memberName): a bus terminal's members are matched by name, so within a
    // terminal every memberName is distinct.
    let terminals: [Terminal; 5] = [
        (
            "engine",
            "Engine operating point: speed set-point and drivetrain load torque",
            &[("rpm", "rpm"), ("loadTorque", "loadTorque")],
        ),
        (
            "bodyPort",
            "The mounts' port to the body: per mount the body point's displacement and velocity in (scene 3, an external body), the mount's force on the body out; connects one to one to EngineMountBody's mount.r, mount.v and mount.F",
            &[("mount.body.r", "r"), ("mount.body.v", "v"), ("mount.F", "F")],
        ),
        (
            "mounts",
            "The engine mounts' characteristics: scales of their stiffness and damping",
            &[
                ("mount.stiffnessScale", "stiffnessScale"),
                ("mount.dampingScale", "dampingScale"),
            ],
        ),
        (
            "powertrain",
            "Motion of the powertrain (housing) centre of gravity",
            &[
                ("powertrain.r", "r"),
                ("powertrain.phi", "phi"),
                ("powertrain.a", "a"),
                ("crankAngle", "crankAngle"),
            ],
        ),
        (
            "comfort",
            "Comfort points of the car body: steering wheel and driver's seat rail accelerations",
            &[("steeringWheel.a", "steeringWheelA"), ("seat.a", "seatA")],
        ),
    ];
    let body: [Terminal; 2] = [
        (
            "bodyPort",
            "The body's port to the mounts: per mount the force on the body in, the body point's displacement, velocity and acceleration out; connects one to one to EngineMountChassis' mount.F, mount.body.r and mount.body.v (scene 3)",
            &[
                ("mount.F", "F"),
                ("mount.r", "r"),
                ("mount.v", "v"),
                ("mount.a", "a"),
            ],
        ),
        terminals[4],
    ];
    let terminals: &[Terminal] = if mask == super::BODY {
        &body
    } else {
        &terminals
    };
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    element(w, "fmiTerminalsAndIcons", &vec![attr("fmiVersion", "3.0")]).write_inner_content(
        |w| {
            w.create_element("Terminals").write_inner_content(|w| {
                for &(name, description, members) in terminals {
                    let terminal = vec![
                        attr("name", name),
                        attr("matchingRule", "bus"),
                        attr("description", description),
                    ];
                    let mut member_names = std::collections::BTreeSet::new();
                    element(w, "Terminal", &terminal).write_inner_content(|w| {
                        for (member, member_name) in members {
                            let v = vars
                                .iter()
                                .find(|v| v.name == *member)
                                .unwrap_or_else(|| fail(&format!("terminal member {member}")));
                            if !member_names.insert(*member_name) {
                                fail(&format!("terminal {name}: memberName {member_name} twice"));
                            }
                            let m = vec![
                                attr("variableName", &v.name),
                                attr("memberName", member_name),
                                attr("variableKind", "signal"),
                            ];
                            element(w, "TerminalMemberVariable", &m).write_empty()?;
                        }
                        Ok(())
                    })?;
                }
                Ok(())
            })?;
            Ok(())
        },
    )?;
    Ok(())
}

/// The Rust map of the 3.0 variables, appended to `variables.rs`.
pub fn rust_map(table: &Value, families: &[Family]) -> String {
    // Both FMUs' variables: value references are unique across the table, and a variable of
    // both FMUs is listed once.
    let mut vars = variables(table, families, super::ENGINE);
    for v in variables(table, families, super::BODY) {
        if !vars.iter().any(|w| w.vr == v.vr) {
            vars.push(v);
        }
    }
    let max = modes_max(&vars);
    let mut r = String::new();
    let _ = writeln!(
        r,
        r#"
/// One variable of the FMI 3.0 model description: a scalar or an array over variables of the
/// 2.0 table (which the instance stores).
#[derive(Debug, Clone, Copy)]
pub struct ArrayVariable {{
    /// FMI 3.0 name, e.g. `mount.F`.
    pub name: &'static str,
    /// FMI 3.0 value reference: the 2.0 value reference of the first element.
    pub vr: u32,
    /// The type as an index into Real, Integer, Boolean, String (the 3.0 types Float64, Int32,
    /// Boolean, String).
    pub type_index: usize,
    /// The elements' indices among the variables of their type ([`REALS`], …), row-major.
    pub indices: &'static [u32],
    /// The array's dimensions as declared (empty for a scalar).
    pub dims: &'static [usize],
    /// The first dimension is the structural parameter `modes.size`: only the first
    /// `modes.size` elements exist.
    pub sized_by_modes: bool,
}}

/// The FMI 3.0 variables beyond the 2.0 table and the map from 3.0 value references to the 2.0
/// table.
pub mod fmi3 {{
    /// Value reference of the independent variable `time` \[s\].
    pub const TIME: u32 = {TIME_VR};
    /// Value reference of the structural parameter `modes.size` (UInt64): the length of the
    /// natural-mode arrays.
    pub const MODES_SIZE: u32 = {MODES_SIZE_VR};
    /// The largest `modes.size` (and its start value): the 2.0 table's natural-mode slots.
    pub const MODES_SIZE_MAX: u64 = {max};
    /// Every 3.0 variable with a 2.0 counterpart, in the order of the model description.
    pub static VARIABLES: &[super::ArrayVariable] = &["#
    );
    for v in &vars {
        let count: usize = v.family.dims.iter().product::<usize>().max(1);
        let indices: Vec<usize> = (0..count).map(|k| v.family.first_vr + k).collect();
        let type_index = ["Real", "Integer", "Boolean", "String"]
            .iter()
            .position(|t| *t == v.family.ty)
            .unwrap_or(0);
        let _ = writeln!(
            r,
            "        super::ArrayVariable {{ name: {:?}, vr: {}, type_index: {type_index}, indices: &{indices:?}, dims: &{:?}, sized_by_modes: {} }},",
            v.name, v.vr, v.family.dims, v.sized_by_modes
        );
    }
    r.push_str("    ];\n}\n");
    if VR_BASE[3] + 1000 > TIME_VR {
        fail("the FMI 3.0 value references of time and modes.size overlap the 2.0 ranges");
    }
    r
}
