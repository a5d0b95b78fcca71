//! The generated FMI 3.0 files read by a strict reader of the 3.0 schema (the `fmi-schema`
//! crate: every attribute and element must be the schema's, so a 2.0 spelling such as
//! `providesDirectionalDerivative` is refused), and the terminals checked against it: bus
//! members distinct by name and every member a variable of the model description.

use engine_mount_chassis::fmi3::{
    BODY_MODEL_DESCRIPTION_XML, BODY_TERMINALS_AND_ICONS_XML, MODEL_DESCRIPTION_XML,
    TERMINALS_AND_ICONS_XML,
};
use fmi_schema::fmi3::{resolve_terminals, Fmi3ModelDescription, Fmi3TerminalsAndIcons};

/// The model description and terminals of each FMI 3.0 FMU the library serves.
fn fmus() -> Vec<(&'static str, &'static str, &'static str)> {
    vec![
        (
            "EngineMountChassis",
            MODEL_DESCRIPTION_XML,
            TERMINALS_AND_ICONS_XML,
        ),
        (
            "EngineMountBody",
            BODY_MODEL_DESCRIPTION_XML,
            BODY_TERMINALS_AND_ICONS_XML,
        ),
    ]
}

#[test]
fn the_3_0_model_descriptions_and_terminals_read_strictly() {
    for (name, xml, terminals_xml) in fmus() {
        let md: Fmi3ModelDescription = fmi_schema::deserialize(xml).unwrap_or_else(|e| {
            panic!("{name}: the strict 3.0 reader refuses the description: {e}")
        });
        assert_eq!(md.fmi_version, "3.0", "{name}");
        let cs = md.co_simulation.as_ref().expect("co-simulation");
        assert_eq!(cs.model_identifier, name);
        assert_eq!(
            cs.provides_directional_derivatives,
            Some(true),
            "{name}: providesDirectionalDerivatives in the 3.0 spelling"
        );
        let terminals: Fmi3TerminalsAndIcons = fmi_schema::deserialize(terminals_xml)
            .unwrap_or_else(|e| panic!("{name}: the strict 3.0 reader refuses the terminals: {e}"));
        let root = terminals.terminals.as_ref().expect("terminals");
        assert!(!root.terminals.is_empty());
        for t in &root.terminals {
            t.validate_matching_rule()
                .unwrap_or_else(|e| panic!("{name}: terminal {}: {e}", t.name));
        }
        if let Err(e) = resolve_terminals(&terminals, &md) {
            panic!("{name}: a terminal member is not a variable: {e:?}");
        }
        assert!(
            !xml.contains("fmi2"),
            "{name}: the 3.0 description names FMI 2.0 functions"
        );
    }
}
