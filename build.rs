//! Generates, from the one variable table `modelDescription/variables.json`, for each of the two
//! FMUs the crate's library serves (the engine FMU and, from the variables tagged `"fmus":
//! [.., "body"]`, the body FMU; one library, told apart by the GUID at instantiation):
//! - `modelDescription.xml` and `body.modelDescription.xml` (packaged into the FMUs),
//! - `variables.rs` (the value-reference table the FMI layer includes, with the unit factors)
//!   and `bindings.rs` (each output and input bound to what it is in the runtime;
//!   `build/bindings.rs`),
//! - `index.html` and `body.index.html` (the FMUs' documentation pages),
//! - `exports.map`, a linker version script that exports exactly the fmi2 and fmi3 functions;
//! - the FMI 3.0 files of both FMUs (`build/fmi3_description.rs`).
//!
//! The GUIDs are hashes of the table's content, so the XML and the binary can never disagree.

use quick_xml::events::{BytesDecl, BytesText, Event};
use quick_xml::Writer;
use serde_json::Value;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

#[path = "build/bindings.rs"]
mod bindings;
#[path = "build/fmi3_description.rs"]
mod fmi3_description;

/// The 34 functions of the FMI 2.0 common and co-simulation API.
const FMI2_FUNCTIONS: [&str; 34] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

const TYPES: [&str; 4] = ["Real", "Integer", "Boolean", "String"];

/// Value references are unique across types (some masters, PyFMI among them, key variables by
/// value reference alone): the XML's value reference of a variable is its index among the
/// variables of its type plus the type's base.
const VR_BASE: [usize; 4] = [0, 1000, 2000, 3000];

fn vr_base(ty: &str) -> usize {
    VR_BASE[TYPES.iter().position(|t| *t == ty).unwrap_or(0)]
}

/// The engine FMU's bit in a variable's `fmus` mask.
const ENGINE: u8 = 1;
/// The body FMU's bit.
const BODY: u8 = 2;

/// One of the FMUs the table describes.
struct Fmu<'a> {
    mask: u8,
    model_name: &'a str,
    identifier: &'a str,
    description: &'a str,
    guid: String,
}

/// One scalar variable after expanding `{i}`/`{j}` families.
struct Scalar {
    /// Which FMUs have the variable (bits [`ENGINE`], [`BODY`]).
    fmus: u8,
    /// Its family in the table.
    family: usize,
    /// The family index `{i}` (1-based), if any.
    first_index: Option<usize>,
    name: String,
    description: String,
    ty: &'static str,
    vr: usize,
    causality: String,
    variability: String,
    start: Option<Value>,
    unit: Option<String>,
    display_unit: Option<String>,
    min: Option<f64>,
    max: Option<f64>,
}

/// A table entry as written: a scalar or a family with `dims`, named for Rust by `rust`.
struct Family {
    rust: String,
    /// The FMI name, with `{i}`/`{j}` placeholders for an array family.
    name: String,
    description: String,
    unit: Option<String>,
    ty: &'static str,
    dims: Vec<usize>,
    first_vr: usize,
    /// Inputs (family `rust` names) this output depends on directly.
    feedthrough: Vec<String>,
    /// Whether the dependency is on the same mount (`{i}`) only.
    per_mount: bool,
}

fn main() {
    let manifest = PathBuf::from(env("CARGO_MANIFEST_DIR"));
    let out = PathBuf::from(env("OUT_DIR"));
    let table_path = manifest.join("modelDescription/variables.json");
    println!("cargo:rerun-if-changed={}", table_path.display());
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=build/fmi3_description.rs");
    println!("cargo:rerun-if-changed=build/bindings.rs");
    write_algorithm_sources(&manifest, &out);

    let text = std::fs::read_to_string(&table_path)
        .unwrap_or_else(|e| fail(&format!("cannot read {}: {e}", table_path.display())));
    let table: Value = serde_json::from_str(&text)
        .unwrap_or_else(|e| fail(&format!("{} is not valid JSON: {e}", table_path.display())));

    let body = table
        .get("bodyModel")
        .unwrap_or_else(|| fail("missing `bodyModel`"));
    let fmus = [
        Fmu {
            mask: ENGINE,
            model_name: str_field(&table, "modelName"),
            identifier: str_field(&table, "modelIdentifier"),
            description: str_field(&table, "description"),
            guid: guid_of(&text),
        },
        Fmu {
            mask: BODY,
            model_name: str_field(body, "modelName"),
            identifier: str_field(body, "modelIdentifier"),
            description: str_field(body, "description"),
            guid: guid_of(&format!("{text}\nbody")),
        },
    ];
    let (scalars, families) = expand(&table);
    for (fmu, prefix) in fmus.iter().zip(["", "body."]) {
        validate(&table, &scalars, &families, fmu.mask);
        write(
            &out.join(format!("{prefix}modelDescription.xml")),
            &model_description(&table, &scalars, &families, fmu),
        );
        write(
            &out.join(format!("{prefix}index.html")),
            &documentation(&scalars, fmu),
        );
    }
    write(
        &out.join("variables.rs"),
        &(rust_table(&table, &scalars, &families, &fmus)
            + &fmi3_description::rust_map(&table, &families)
            + &bindings::rust_units(&table)),
    );
    write(
        &out.join("bindings.rs"),
        &bindings::rust_bindings(&table, &families),
    );
    fmi3_description::write_files(&out, &table, &families, &fmus);

    let mut map = String::from("{\n  global:\n");
    for f in FMI2_FUNCTIONS
        .iter()
        .chain(&fmi3_description::FMI3_FUNCTIONS)
    {
        let _ = writeln!(map, "    {f};");
    }
    // fmi-sys (fmi2 feature) defines a #[no_mangle] `callback_log` that rustc would export too.
    map.push_str("  local:\n    callback_log;\n    *;\n};\n");
    let map_path = out.join("exports.map");
    write(&map_path, &map);
    if std::env::var("CARGO_CFG_TARGET_OS").as_deref() == Ok("windows") {
        // The PE linker would export what rustc lists in its own .def file (every #[no_mangle]
        // function, fmi-sys' callback_log included); this .def file names the fmi2 and fmi3 functions alone.
        let mut def = String::from("EXPORTS\n");
        for f in FMI2_FUNCTIONS
            .iter()
            .chain(&fmi3_description::FMI3_FUNCTIONS)
        {
            let _ = writeln!(def, "    {f}");
        }
        let def_path = out.join("exports.def");
        write(&def_path, &def);
        println!("cargo:rustc-cdylib-link-arg={}", def_path.display());
        // No DLLs beyond the system's: the GCC runtime and winpthread are linked in.
        println!("cargo:rustc-cdylib-link-arg=-static-libgcc");
        println!("cargo:rustc-cdylib-link-arg=-static");
    } else {
        println!(
            "cargo:rustc-cdylib-link-arg=-Wl,--version-script={}",
            map_path.display()
        );
    }
}

fn env(key: &str) -> String {
    std::env::var(key).unwrap_or_else(|_| fail(&format!("{key} is not set")))
}

fn fail(msg: &str) -> ! {
    eprintln!("build.rs: {msg}");
    std::process::exit(1)
}

fn write(path: &Path, content: &str) {
    std::fs::write(path, content)
        .unwrap_or_else(|e| fail(&format!("cannot write {}: {e}", path.display())));
}

fn str_field<'a>(v: &'a Value, key: &str) -> &'a str {
    v.get(key)
        .and_then(Value::as_str)
        .unwrap_or_else(|| fail(&format!("missing string field `{key}` in {v}")))
}

fn opt_str(v: &Value, key: &str) -> Option<String> {
    v.get(key).and_then(Value::as_str).map(str::to_owned)
}

/// A content-derived GUID: two FNV-1a 64-bit hashes with different offsets, formatted as a UUID.
fn guid_of(text: &str) -> String {
    let fnv = |offset: u64| {
        text.bytes().fold(offset, |h, b| {
            (h ^ u64::from(b)).wrapping_mul(0x100000001b3)
        })
    };
    let a = fnv(0xcbf29ce484222325);
    let b = fnv(0x84222325cbf29ce4);
    format!(
        "{{{:08x}-{:04x}-{:04x}-{:04x}-{:012x}}}",
        a >> 32,
        (a >> 16) & 0xffff,
        a & 0xffff,
        b >> 48,
        b & 0xffff_ffff_ffff
    )
}

fn expand(table: &Value) -> (Vec<Scalar>, Vec<Family>) {
    let entries = table
        .get("variables")
        .and_then(Value::as_array)
        .unwrap_or_else(|| fail("`variables` must be an array"));
    let mut next_vr: BTreeMap<&str, usize> = TYPES.iter().map(|t| (*t, 0)).collect();
    let mut scalars = Vec::new();
    let mut families = Vec::new();
    for e in entries {
        let ty_name = str_field(e, "type");
        let ty = *TYPES
            .iter()
            .find(|t| **t == ty_name)
            .unwrap_or_else(|| fail(&format!("unknown type {ty_name}")));
        let dims: Vec<usize> = e
            .get("dims")
            .and_then(Value::as_array)
            .map(|d| d.iter().map(|x| x.as_u64().unwrap_or(0) as usize).collect())
            .unwrap_or_default();
        if dims.contains(&0) || dims.len() > 2 {
            fail(&format!("bad dims in {}", str_field(e, "name")));
        }
        let first_vr = next_vr[ty];
        let fmus = match e.get("fmus").and_then(Value::as_array) {
            None => ENGINE,
            Some(list) => list.iter().fold(0, |m, f| {
                m | match f.as_str() {
                    Some("engine") => ENGINE,
                    Some("body") => BODY,
                    _ => fail(&format!("unknown FMU {f} in {}", str_field(e, "name"))),
                }
            }),
        };
        let feedthrough = e.get("feedthrough");
        let family = families.len();
        families.push(Family {
            rust: str_field(e, "rust").to_owned(),
            name: str_field(e, "name").to_owned(),
            description: str_field(e, "description").to_owned(),
            unit: opt_str(e, "unit"),
            ty,
            dims: dims.clone(),
            first_vr,
            feedthrough: feedthrough
                .and_then(|f| f.get("inputs"))
                .and_then(Value::as_array)
                .map(|l| {
                    l.iter()
                        .filter_map(Value::as_str)
                        .map(str::to_owned)
                        .collect()
                })
                .unwrap_or_default(),
            per_mount: feedthrough
                .and_then(|f| f.get("perMount"))
                .and_then(Value::as_bool)
                .unwrap_or(false),
        });
        let indices: Vec<Vec<usize>> = match dims.as_slice() {
            [] => vec![vec![]],
            [n] => (1..=*n).map(|i| vec![i]).collect(),
            [n, m] => (1..=*n)
                .flat_map(|i| (1..=*m).map(move |j| vec![i, j]))
                .collect(),
            _ => unreachable!(),
        };
        for idx in indices {
            let subst = |s: &str| {
                let mut s = s.to_owned();
                if let Some(i) = idx.first() {
                    s = s.replace("{i}", &i.to_string());
                }
                if let Some(j) = idx.get(1) {
                    s = s.replace("{j}", &j.to_string());
                }
                s
            };
            let vr = next_vr[ty];
            *next_vr.get_mut(ty).unwrap_or_else(|| fail("type")) += 1;
            scalars.push(Scalar {
                fmus,
                family,
                first_index: idx.first().copied(),
                name: subst(str_field(e, "name")),
                description: subst(str_field(e, "description")),
                ty,
                vr,
                causality: str_field(e, "causality").to_owned(),
                variability: str_field(e, "variability").to_owned(),
                start: e.get("start").cloned(),
                unit: opt_str(e, "unit"),
                display_unit: opt_str(e, "displayUnit"),
                min: e.get("min").and_then(Value::as_f64),
                max: e.get("max").and_then(Value::as_f64),
            });
        }
    }
    if let Some((ty, n)) = next_vr.iter().find(|(_, n)| **n >= VR_BASE[1]) {
        fail(&format!(
            "{n} {ty} variables do not fit below the next type's value-reference base"
        ));
    }
    (scalars, families)
}

/// The combinations fmpy's validator and the standard require, in the FMU `mask`.
fn validate(table: &Value, scalars: &[Scalar], families: &[Family], mask: u8) {
    let units: Vec<&str> = table
        .get("units")
        .and_then(Value::as_array)
        .map(|u| u.iter().map(|x| str_field(x, "name")).collect())
        .unwrap_or_default();
    let mut names = std::collections::BTreeSet::new();
    for f in families {
        for input in &f.feedthrough {
            if !families.iter().any(|g| &g.rust == input) {
                fail(&format!(
                    "{} lists unknown feedthrough input {input}",
                    f.name
                ));
            }
        }
    }
    for s in scalars.iter().filter(|s| s.fmus & mask != 0) {
        if !names.insert(s.name.clone()) {
            fail(&format!("duplicate variable name {}", s.name));
        }
        let needs_start = matches!(s.causality.as_str(), "input" | "parameter");
        if needs_start && s.start.is_none() {
            fail(&format!("{} ({}) needs a start value", s.name, s.causality));
        }
        if matches!(s.causality.as_str(), "output" | "calculatedParameter") && s.start.is_some() {
            fail(&format!(
                "{} {} is calculated and must not have a start value",
                s.causality, s.name
            ));
        }
        if let Some(u) = &s.unit {
            if !units.contains(&u.as_str()) {
                fail(&format!("{} uses undefined unit {u}", s.name));
            }
        }
        if s.ty != "Real" && s.variability == "continuous" {
            fail(&format!("{} of type {} cannot be continuous", s.name, s.ty));
        }
    }
}

/// A start value as XML attribute text (quick-xml escapes it).
fn value_text(v: &Value) -> String {
    match v {
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => s.clone(),
        other => fail(&format!("unsupported start value {other}")),
    }
}

/// Attributes in the order given (quick-xml escapes the values).
type Attributes = Vec<(String, String)>;

fn attr(key: &str, value: impl ToString) -> (String, String) {
    (key.to_string(), value.to_string())
}

fn element<'w>(
    w: &'w mut Writer<Vec<u8>>,
    name: &'w str,
    attributes: &'w Attributes,
) -> quick_xml::writer::ElementWriter<'w, Vec<u8>> {
    w.create_element(name)
        .with_attributes(attributes.iter().map(|(k, v)| (k.as_str(), v.as_str())))
}

fn model_description(table: &Value, scalars: &[Scalar], families: &[Family], fmu: &Fmu) -> String {
    let mut w = Writer::new_with_indent(Vec::new(), b' ', 2);
    write_model_description(&mut w, table, scalars, families, fmu)
        .unwrap_or_else(|e| fail(&format!("writing modelDescription.xml: {e}")));
    let mut xml = String::from_utf8(w.into_inner()).expect("quick-xml writes UTF-8");
    xml.push('\n');
    xml
}

/// The parts of a model description that FMI 2.0 and 3.0 share, in the order both schemas
/// want them: `UnitDefinitions`, `LogCategories`, `DefaultExperiment`.
/// Writes the unit definitions, the type definitions `types` writes (none in FMI 2.0), the log
/// categories and the default experiment, in the order both schemas have them.
fn write_units_categories_experiment(
    w: &mut Writer<Vec<u8>>,
    table: &Value,
    types: &dyn Fn(&mut Writer<Vec<u8>>) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let array = |key: &str| -> Vec<Value> {
        table
            .get(key)
            .and_then(Value::as_array)
            .cloned()
            .unwrap_or_default()
    };
    w.create_element("UnitDefinitions")
        .write_inner_content(|w| {
            for u in array("units") {
                let name = vec![attr("name", str_field(&u, "name"))];
                element(w, "Unit", &name).write_inner_content(|w| {
                    let mut base: Attributes = u
                        .get("base")
                        .and_then(Value::as_object)
                        .into_iter()
                        .flatten()
                        .map(|(k, v)| attr(k, v))
                        .collect();
                    if let Some(f) = u.get("factor").and_then(Value::as_f64) {
                        base.push(attr("factor", format!("{f:?}")));
                    }
                    element(w, "BaseUnit", &base).write_empty()?;
                    for d in u
                        .get("display")
                        .and_then(Value::as_array)
                        .into_iter()
                        .flatten()
                    {
                        let factor = d.get("factor").and_then(Value::as_f64).unwrap_or(1.0);
                        let display = vec![
                            attr("name", str_field(d, "name")),
                            attr("factor", format!("{factor:?}")),
                        ];
                        element(w, "DisplayUnit", &display).write_empty()?;
                    }
                    Ok(())
                })?;
            }
            Ok(())
        })?;
    types(w)?;
    w.create_element("LogCategories").write_inner_content(|w| {
        for c in array("logCategories") {
            let category = vec![
                attr("name", str_field(&c, "name")),
                attr("description", str_field(&c, "description")),
            ];
            element(w, "Category", &category).write_empty()?;
        }
        Ok(())
    })?;
    if let Some(de) = table.get("defaultExperiment").and_then(Value::as_object) {
        let experiment: Attributes = de.iter().map(|(k, v)| attr(k, v)).collect();
        element(w, "DefaultExperiment", &experiment).write_empty()?;
    }
    Ok(())
}

/// The direct dependencies of output `s` among the FMU's variables `visible` (1-based indices of
/// the XML's variable list), as its family's `feedthrough` declares them.
fn feedthrough_of(s: &Scalar, visible: &[&Scalar], families: &[Family]) -> Vec<usize> {
    let family = &families[s.family];
    visible
        .iter()
        .enumerate()
        .filter(|(_, v)| {
            family.feedthrough.contains(&families[v.family].rust)
                && (!family.per_mount || v.first_index == s.first_index)
        })
        .map(|(i, _)| i + 1)
        .collect()
}

fn write_model_description(
    w: &mut Writer<Vec<u8>>,
    table: &Value,
    scalars: &[Scalar],
    families: &[Family],
    fmu: &Fmu,
) -> std::io::Result<()> {
    let scalars: Vec<&Scalar> = scalars.iter().filter(|s| s.fmus & fmu.mask != 0).collect();
    w.write_event(Event::Decl(BytesDecl::new("1.0", Some("UTF-8"), None)))?;
    let root = vec![
        attr("fmiVersion", "2.0"),
        attr("modelName", fmu.model_name),
        attr("guid", &fmu.guid),
        attr("description", fmu.description),
        attr("author", str_field(table, "author")),
        attr("version", str_field(table, "version")),
        attr("generationTool", "engine_mount_chassis build.rs"),
        attr("variableNamingConvention", "structured"),
        attr("numberOfEventIndicators", 0),
    ];
    element(w, "fmiModelDescription", &root).write_inner_content(|w| {
        let co_simulation = vec![
            attr("modelIdentifier", fmu.identifier),
            attr("needsExecutionTool", false),
            attr("canHandleVariableCommunicationStepSize", true),
            attr("canInterpolateInputs", true),
            attr("maxOutputDerivativeOrder", 0),
            attr("canRunAsynchronuously", false),
            attr("canBeInstantiatedOnlyOncePerProcess", false),
            attr("canNotUseMemoryManagementFunctions", true),
            attr("canGetAndSetFMUstate", true),
            attr("canSerializeFMUstate", true),
            attr("providesDirectionalDerivative", true),
        ];
        element(w, "CoSimulation", &co_simulation).write_empty()?;
        write_units_categories_experiment(w, table, &|_| Ok(()))?;
        w.create_element("ModelVariables")
            .write_inner_content(|w| {
                for (index, s) in scalars.iter().enumerate() {
                    w.write_event(Event::Comment(BytesText::from_escaped(format!(
                        " index {} ",
                        index + 1
                    ))))?;
                    let variable = vec![
                        attr("name", &s.name),
                        attr("valueReference", s.vr + vr_base(s.ty)),
                        attr("causality", &s.causality),
                        attr("variability", &s.variability),
                        attr("description", &s.description),
                    ];
                    element(w, "ScalarVariable", &variable).write_inner_content(|w| {
                        let mut typed = Attributes::new();
                        if let Some(v) = &s.start {
                            typed.push(attr("start", value_text(v)));
                        }
                        if let Some(u) = &s.unit {
                            typed.push(attr("unit", u));
                        }
                        if let Some(u) = &s.display_unit {
                            typed.push(attr("displayUnit", u));
                        }
                        if let Some(m) = s.min {
                            typed.push(attr("min", number_text(s.ty, m)));
                        }
                        if let Some(m) = s.max {
                            typed.push(attr("max", number_text(s.ty, m)));
                        }
                        element(w, s.ty, &typed).write_empty()?;
                        Ok(())
                    })?;
                }
                Ok(())
            })?;
        let outputs: Vec<(usize, String)> = scalars
            .iter()
            .enumerate()
            .filter(|(_, s)| s.causality == "output")
            .map(|(i, s)| {
                let direct = feedthrough_of(s, &scalars, families);
                let list = direct.iter().map(usize::to_string).collect::<Vec<_>>();
                (i + 1, list.join(" "))
            })
            .collect();
        // FMI 2.0 §2.2.8: the initial unknowns are the outputs and the calculated parameters,
        // in index order.
        let initial_unknowns: Vec<usize> = scalars
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s.causality.as_str(), "output" | "calculatedParameter"))
            .map(|(i, _)| i + 1)
            .collect();
        let initial_unknowns: Vec<(usize, String)> = initial_unknowns
            .into_iter()
            .map(|i| (i, String::new()))
            .collect();
        // At the end of initialisation the outputs describe the static equilibrium, which
        // depends on every parameter and on the load torque and mount stiffness scales; with initialization.periodic they describe the periodic orbit, and
        // the natural modes' damping depends on the mount damping scales: so every input is a
        // dependency (a test checks that none is missing).
        let knowns = scalars
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(s.causality.as_str(), "parameter" | "input"))
            .map(|(i, _)| (i + 1).to_string())
            .collect::<Vec<_>>()
            .join(" ");
        w.create_element("ModelStructure")
            .write_inner_content(|w| {
                // Outputs are computed from the state at the communication point, in fmi2DoStep
                // (and at initialisation): an input set at a communication point acts from there
                // on and changes no output before the next step — except the interface inputs
                // the table declares as `feedthrough` (a body's motion at the mounts, the mount
                // forces on a body), through which the outputs respond at once, as a coupling
                // algorithm needs.
                for (list, unknowns) in [
                    ("Outputs", &outputs),
                    ("InitialUnknowns", &initial_unknowns),
                ] {
                    w.create_element(list).write_inner_content(|w| {
                        for (i, direct) in unknowns {
                            let dependencies = if list == "Outputs" {
                                direct.as_str()
                            } else {
                                knowns.as_str()
                            };
                            let unknown =
                                vec![attr("index", i), attr("dependencies", dependencies)];
                            element(w, "Unknown", &unknown).write_empty()?;
                        }
                        Ok(())
                    })?;
                }
                Ok(())
            })?;
        Ok(())
    })?;
    Ok(())
}

fn number_text(ty: &str, v: f64) -> String {
    if ty == "Integer" {
        format!("{}", v as i64)
    } else {
        format!("{v:?}")
    }
}

fn rust_causality(c: &str) -> &'static str {
    match c {
        "input" => "Causality::Input",
        "output" => "Causality::Output",
        "parameter" => "Causality::Parameter",
        "calculatedParameter" => "Causality::CalculatedParameter",
        "local" => "Causality::Local",
        other => fail(&format!("unsupported causality {other}")),
    }
}

fn rust_variability(v: &str) -> &'static str {
    match v {
        "constant" => "Variability::Constant",
        "fixed" => "Variability::Fixed",
        "tunable" => "Variability::Tunable",
        "discrete" => "Variability::Discrete",
        "continuous" => "Variability::Continuous",
        other => fail(&format!("unsupported variability {other}")),
    }
}

fn rust_table(table: &Value, scalars: &[Scalar], families: &[Family], fmus: &[Fmu; 2]) -> String {
    let mut r = String::from(
        "// Generated by build.rs from modelDescription/variables.json. Do not edit.\n\n",
    );
    let _ = writeln!(
        r,
        "/// `modelIdentifier` of the engine FMU: its binary name.\npub const MODEL_IDENTIFIER: &str = {:?};",
        fmus[0].identifier
    );
    let _ = writeln!(r, "/// The GUID of the engine FMU's `modelDescription.xml` (a hash of the variable table).\npub const GUID: &str = {:?};", fmus[0].guid);
    let _ = writeln!(
        r,
        "/// `modelIdentifier` of the body FMU.\npub const BODY_MODEL_IDENTIFIER: &str = {:?};",
        fmus[1].identifier
    );
    let _ = writeln!(
        r,
        "/// The GUID of the body FMU's `modelDescription.xml`.\npub const BODY_GUID: &str = {:?};",
        fmus[1].guid
    );
    let _ = writeln!(
        r,
        "/// What the XML adds to a variable's index among its type ([`real`], [`integer`], …) to\n/// make its value reference, per type Real, Integer, Boolean, String: value references are\n/// unique across types.\npub const VR_BASE: [u32; 4] = {VR_BASE:?};"
    );
    r.push_str(&log_categories(table));
    for ty in TYPES {
        let module = ty.to_lowercase();
        let _ = writeln!(
            r,
            "\n/// Value references of the {ty} variables (indices into [`{}S`]).",
            ty.to_uppercase()
        );
        let _ = writeln!(r, "pub mod {module} {{");
        for f in families.iter().filter(|f| f.ty == ty) {
            let _ = writeln!(r, "{}", family_doc(f));
            match f.dims.as_slice() {
                [] => {
                    let _ = writeln!(r, "    pub const {}: u32 = {};", f.rust, f.first_vr);
                }
                [n] => {
                    let vrs: Vec<usize> = (0..*n).map(|i| f.first_vr + i).collect();
                    let _ = writeln!(r, "    pub const {}: [u32; {n}] = {vrs:?};", f.rust);
                }
                [n, m] => {
                    let rows: Vec<Vec<usize>> = (0..*n)
                        .map(|i| (0..*m).map(|j| f.first_vr + i * m + j).collect())
                        .collect();
                    let _ = writeln!(r, "    pub const {}: [[u32; {m}]; {n}] = {rows:?};", f.rust);
                }
                _ => unreachable!(),
            }
        }
        r.push_str("}\n");
        let rust_ty = match ty {
            "Real" => "f64",
            "Integer" => "i32",
            "Boolean" => "bool",
            _ => "&'static str",
        };
        let _ = writeln!(r, "\n/// The {ty} variables, indexed by value reference.");
        let _ = writeln!(
            r,
            "pub static {}S: &[Variable<{rust_ty}>] = &[",
            ty.to_uppercase()
        );
        for s in scalars.iter().filter(|s| s.ty == ty) {
            let start = match (&s.start, ty) {
                (None, "Real") => "0.0".to_owned(),
                (None, "Integer") => "0".to_owned(),
                (None, "Boolean") => "false".to_owned(),
                (None, _) => "\"\"".to_owned(),
                (Some(Value::Number(n)), "Real") => format!("{:?}", n.as_f64().unwrap_or(0.0)),
                (Some(Value::Number(n)), "Integer") => n.to_string(),
                (Some(Value::Bool(b)), "Boolean") => b.to_string(),
                (Some(Value::String(st)), "String") => format!("{st:?}"),
                (Some(v), _) => fail(&format!("start {v} does not fit {} of type {ty}", s.name)),
            };
            let bound = |b: Option<f64>| match (b, ty) {
                (Some(v), "Real") => format!("Some({v:?})"),
                (Some(v), "Integer") => format!("Some({})", v as i64),
                _ => "None".to_owned(),
            };
            let _ = writeln!(
                r,
                "    Variable {{ name: {:?}, vr: {}, index: {}, fmus: {}, causality: {}, variability: {}, start: {start}, min: {}, max: {} }},",
                s.name,
                s.vr + vr_base(s.ty),
                s.vr,
                s.fmus,
                rust_causality(&s.causality),
                rust_variability(&s.variability),
                if matches!(ty, "Real" | "Integer") { bound(s.min) } else { "None".to_owned() },
                if matches!(ty, "Real" | "Integer") { bound(s.max) } else { "None".to_owned() },
            );
        }
        r.push_str("];\n");
    }
    r.push_str(&parameters_struct(scalars, families));
    r
}

/// The `///` line(s) of a value-reference constant: the FMI name (the name pattern for an
/// array family, whose FMI indices are 1-based while the Rust array's are 0-based), the unit
/// and the table's description, with brackets escaped so rustdoc does not read them as links.
fn family_doc(f: &Family) -> String {
    let escape = |s: &str| s.replace('[', "\\[").replace(']', "\\]");
    let unit = f
        .unit
        .as_ref()
        .map(|u| format!(" \\[{u}\\]"))
        .unwrap_or_default();
    let mut doc = format!("    /// `{}`{unit}: {}", f.name, escape(&f.description));
    match f.dims.as_slice() {
        [] => {}
        [n] => {
            let _ = write!(
                doc,
                "\n    ///\n    /// Element `[i - 1]` is `{}`, i = 1..={n}.",
                f.name
            );
        }
        [n, m] => {
            let _ = write!(
                doc,
                "\n    ///\n    /// Element `[i - 1][j - 1]` is `{}`, i = 1..={n}, j = 1..={m}.",
                f.name
            );
        }
        _ => unreachable!(),
    }
    doc
}

/// `LogCategory`: the log categories of `modelDescription.xml` as an enum (variant names are the
/// category names without their `log` prefix), with their names in [`LOG_CATEGORIES`].
fn log_categories(table: &Value) -> String {
    let names: Vec<&str> = table
        .get("logCategories")
        .and_then(Value::as_array)
        .map(|c| c.iter().map(|x| str_field(x, "name")).collect())
        .unwrap_or_default();
    let mut variants = String::new();
    let mut all = String::new();
    for name in &names {
        let variant = name
            .strip_prefix("log")
            .unwrap_or_else(|| fail(&format!("log category {name} must start with `log`")));
        let _ = writeln!(variants, "    /// `{name}`\n    {variant},");
        let _ = write!(all, "LogCategory::{variant}, ");
    }
    format!(
        r#"/// Log categories declared in `modelDescription.xml`, indexed by [`LogCategory`].
pub const LOG_CATEGORIES: &[&str] = &{names:?};

/// A log category of `modelDescription.xml`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LogCategory {{
{variants}}}

impl LogCategory {{
    /// Every category, in the order of [`LOG_CATEGORIES`].
    pub const ALL: &[LogCategory] = &[{all}];

    /// The category's name in `modelDescription.xml`.
    pub fn name(self) -> &'static str {{
        LOG_CATEGORIES[self as usize]
    }}
}}
"#
    )
}

/// `Parameters`: every scalar parameter as a typed field named after its `rust` name, with the
/// FMI name for serde; `Default` reads the start values from the tables above, so the defaults
/// live in the variable table alone.
fn parameters_struct(scalars: &[Scalar], families: &[Family]) -> String {
    let mut fields = String::new();
    let mut from_values = String::new();
    for s in scalars.iter().filter(|s| s.causality == "parameter") {
        let family = families
            .iter()
            .find(|f| f.ty == s.ty && f.dims.is_empty() && f.first_vr == s.vr)
            .unwrap_or_else(|| fail(&format!("parameter {} must be a scalar", s.name)));
        let field = family.rust.to_lowercase();
        let (rust_ty, read) = match s.ty {
            "Real" => ("f64", format!("reals[{}]", s.vr)),
            "Integer" => ("i32", format!("integers[{}]", s.vr)),
            "Boolean" => ("bool", format!("booleans[{}]", s.vr)),
            _ => ("String", format!("strings[{}].as_ref().to_owned()", s.vr)),
        };
        let unit = s
            .unit
            .as_ref()
            .map(|u| format!(" \\[{u}\\]"))
            .unwrap_or_default();
        let _ = writeln!(
            fields,
            "    /// `{}`{unit}: {}\n    #[serde(rename = {:?})]\n    pub {field}: {rust_ty},",
            s.name,
            s.description.replace('[', "\\[").replace(']', "\\]"),
            s.name
        );
        let _ = writeln!(from_values, "            {field}: {read},");
    }
    format!(
        r#"
/// Every parameter of the model description as one typed structure. Serde names are the FMI
/// names; unknown names are refused and missing ones take their start values.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct Parameters {{
{fields}}}

impl Parameters {{
    /// The parameters among per-type values indexed by value reference (as [`REALS`], …).
    pub fn from_values<S: AsRef<str>>(
        reals: &[f64],
        integers: &[i32],
        booleans: &[bool],
        strings: &[S],
    ) -> Self {{
        Self {{
{from_values}        }}
    }}
}}

impl Default for Parameters {{
    /// The start values of the variable table.
    fn default() -> Self {{
        let reals: Vec<f64> = REALS.iter().map(|v| v.start).collect();
        let integers: Vec<i32> = INTEGERS.iter().map(|v| v.start).collect();
        let booleans: Vec<bool> = BOOLEANS.iter().map(|v| v.start).collect();
        let strings: Vec<&str> = STRINGS.iter().map(|v| v.start).collect();
        Self::from_values(&reals, &integers, &booleans, &strings)
    }}
}}
"#
    )
}

/// Text escaped for the documentation page's HTML.
fn xml_escape(s: &str) -> String {
    quick_xml::escape::escape(s).into_owned()
}

fn documentation(scalars: &[Scalar], fmu: &Fmu) -> String {
    let mut h = String::new();
    let name = xml_escape(fmu.model_name);
    let guid = &fmu.guid;
    let _ = writeln!(
        h,
        "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>{name}</title>\n<style>body{{font-family:sans-serif;max-width:70em;margin:2em auto}}table{{border-collapse:collapse}}td,th{{border:1px solid #bbb;padding:3px 6px;text-align:left}}</style></head><body>"
    );
    let _ = writeln!(h, "<h1>{name}</h1>\n<p>{}</p>", xml_escape(fmu.description));
    let _ = writeln!(h, "<p>FMI 2.0 co-simulation, GUID <code>{guid}</code>.</p>");
    if fmu.mask == ENGINE {
        h.push_str(
        "<h2>Scenes</h2>\n<ul><li><b>1</b>: engine on rigid ground: monoblock and housing (with gearbox) as rigid bodies \
         connected by ring carriers, on nonlinear engine mounts fixed to ground (paper Table 1, left column).</li>\
         <li><b>2</b>: engine in the elastic car body: the mounts connect the housing brackets to the mount nodes of the \
         Craig-Bampton reduced FE body (paper Table 1, middle column); adds the steering-wheel and seat-rail accelerations \
         (zero in scene 1). The body is linear about a reference state carrying its own weight, so only the mount forces \
         act on it. The reduction runs at instantiation (parameters <code>chassis.*</code>) and is cached in the user's \
         cache directory unless disabled.</li></ul>\n\
         <h2>Units and frames</h2>\n<p>SI inside. The vehicle frame is ISO 8855: x forward, y left, z up, origin at the \
         front axle centre on the ground plane; the engine is transverse with the crank axis along y. Engine speed is given \
         in rpm (base unit rad/s); angles are in rad with display unit deg, displacements in m with display unit mm.</p>\n\
         <h2>Inputs between communication points</h2>\n<p>Every continuous input (<code>rpm</code>, <code>loadTorque</code>, \
         the mount scales) is a linear signal between communication points, decided when <code>fmi2DoStep</code> starts: \
         a value with a derivative (<code>fmi2SetRealInputDerivatives</code>) is that ramp; a derivative alone continues \
         from the value reached; values alone get a first-order hold (if the last three lie on a line their slope \
         continues, otherwise the value is held); nothing set keeps the signal in force. <code>rpm</code> is a speed \
         set-point that the crank follows critically damped with time constant <code>crank.speedTimeConstant</code>, so \
         a jump becomes a smooth speed change.</p>\n",
    );
    } else {
        h.push_str(
            "<h2>The body alone</h2>\n<p>The Craig-Bampton reduced body on its suspension, linear about a reference \
             state carrying its own weight: the forces <code>mount[i].F</code> on it at the mount points move it. It starts \
             in static equilibrium under the forces given at initialisation and integrates its modal equations exactly for \
             inputs that are linear over a step (set <code>fmi2SetRealInputDerivatives</code> for the force ramps). Units SI, \
             vehicle frame ISO 8855.</p>\n",
        );
    }
    h.push_str("<h2>Variables</h2>\n<table><tr><th>name</th><th>type</th><th>causality</th><th>variability</th><th>start</th><th>unit</th><th>description</th></tr>\n");
    for s in scalars.iter().filter(|s| s.fmus & fmu.mask != 0) {
        let _ = writeln!(
            h,
            "<tr><td><code>{}</code></td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td><td>{}</td></tr>",
            xml_escape(&s.name),
            s.ty,
            s.causality,
            s.variability,
            s.start.as_ref().map(value_text).unwrap_or_default(),
            s.unit.as_deref().map(xml_escape).unwrap_or_default(),
            xml_escape(&s.description)
        );
    }
    h.push_str("</table>\n</body></html>\n");
    h
}

/// The folders whose code turns a body description into a reduced body (elements, decks, the
/// procedural chassis, eigensolvers, the reduction), concatenated in path order into
/// `algorithm_sources.txt`: `cms::cache` hashes it into every cache key, so a reduction computed
/// by other code is never served, and a new file in these folders is covered without a list to
/// keep up to date.
fn write_algorithm_sources(manifest: &Path, out: &Path) {
    fn collect(dir: &Path, files: &mut Vec<PathBuf>) {
        let entries = std::fs::read_dir(dir)
            .unwrap_or_else(|e| fail(&format!("cannot list {}: {e}", dir.display())));
        for entry in entries {
            let path = entry
                .unwrap_or_else(|e| fail(&format!("cannot list {}: {e}", dir.display())))
                .path();
            if path.is_dir() {
                collect(&path, files);
            } else if path.extension().is_some_and(|x| x == "rs") {
                files.push(path);
            }
        }
    }
    let mut files = Vec::new();
    for room in ["fe", "nastran", "chassis", "eigen", "cms"] {
        let dir = manifest.join("src").join(room);
        println!("cargo:rerun-if-changed={}", dir.display());
        collect(&dir, &mut files);
    }
    files.sort();
    let mut text = String::new();
    for path in &files {
        let rel = path.strip_prefix(manifest).unwrap_or(path);
        text += &format!("// {}\n", rel.display());
        text += &std::fs::read_to_string(path)
            .unwrap_or_else(|e| fail(&format!("cannot read {}: {e}", path.display())));
    }
    write(&out.join("algorithm_sources.txt"), &text);
}
