//! Device parameters from files: the template `devices/twin-pantograph.toml` is exactly the spec
//! defaults, a subset overrides only its fields, and bad input (unknown field, wrong type, invalid
//! value) is an error naming the field — from a device file and from a scene's `[device]` table.

use haptic2d::device::DeviceParams;
use haptic2d::scene::{device_params_from_toml, Scene, SceneErrors};
use std::path::PathBuf;

fn template_path() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../devices/twin-pantograph.toml")
}

fn template() -> String {
    std::fs::read_to_string(template_path()).expect("the template devices/twin-pantograph.toml")
}

fn device_errors(text: &str) -> SceneErrors {
    match device_params_from_toml(text, "my-device.toml", None) {
        Ok(p) => panic!("expected an error for:\n{text}\ngot {p:?}"),
        Err(e) => e,
    }
}

/// Asserts that one error is on exactly `field`, its message contains `what`, it has a fix, and
/// the display names the file.
fn assert_field_error(e: &SceneErrors, field: &str, what: &str) {
    let shown = e.to_string();
    assert!(shown.starts_with("my-device.toml"), "file named: {shown}");
    assert!(
        e.errors
            .iter()
            .any(|x| x.field == field && x.message.contains(what) && !x.fix.is_empty()),
        "no error on `{field}` containing `{what}`:\n{shown}"
    );
}

#[test]
fn template_is_exactly_the_spec_defaults() {
    let p = device_params_from_toml(&template(), "devices/twin-pantograph.toml", None)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(p, DeviceParams::default());
}

#[test]
fn template_lists_every_field_with_a_unit_comment() {
    let text = template();
    let parsed: toml::Table = toml::from_str(&text).unwrap();
    let device = parsed["device"].as_table().expect("a [device] table");
    let toml::Value::Table(all) = toml::Value::try_from(DeviceParams::default()).unwrap() else {
        panic!("DeviceParams serializes to a table");
    };
    let listed: Vec<&String> = device.keys().collect();
    let fields: Vec<&String> = all.keys().collect();
    assert_eq!(listed, fields, "the template lists every field, no more");
    // FIELDS (names + units) covers the same fields in declaration order.
    let mut names: Vec<&str> = DeviceParams::FIELDS.iter().map(|(n, _)| *n).collect();
    names.sort_unstable();
    let mut keys: Vec<&str> = all.keys().map(|k| k.as_str()).collect();
    keys.sort_unstable();
    assert_eq!(names, keys);
    // Each field's line carries its unit in the comment.
    for (name, unit) in DeviceParams::FIELDS {
        let line = text
            .lines()
            .find(|l| l.starts_with(&format!("{name} =")))
            .unwrap_or_else(|| panic!("no line for {name}"));
        let comment = line.split_once('#').map(|c| c.1).unwrap_or("");
        assert!(
            comment.contains(unit),
            "the comment of {name} gives its unit {unit}: `{line}`"
        );
    }
}

#[test]
fn a_subset_overrides_only_those_fields_in_both_forms() {
    let expect = DeviceParams {
        l2: 0.14,
        tau_max: 0.3,
        observer_gain: [50.0, 50.0, 40.0],
        ..DeviceParams::default()
    };
    for text in [
        "l2 = 0.14\ntau_max = 0.3\nobserver_gain = [50, 50, 40]\n",
        "# my rig\n[device]\nl2 = 0.14\ntau_max = 0.3\nobserver_gain = [50.0, 50.0, 40.0]\n",
    ] {
        let p =
            device_params_from_toml(text, "my-device.toml", None).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(p, expect, "{text}");
    }
    // An empty file is the spec defaults.
    assert_eq!(
        device_params_from_toml("", "my-device.toml", None).unwrap(),
        DeviceParams::default()
    );
}

#[test]
fn unknown_field_is_named_with_the_valid_names() {
    let e = device_errors("l1 = 0.1\nlink_length = 0.1\n");
    assert_field_error(&e, "link_length", "unknown device parameter");
    assert!(e.errors[0].fix.contains("l1, l2"), "{e}");
    let e = device_errors("[device]\nr_crank = 0.02\n");
    assert_field_error(&e, "device.r_crank", "unknown device parameter");
}

#[test]
fn wrong_type_names_the_field() {
    let e = device_errors("[device]\nl1 = \"ten centimetres\"\n");
    assert_field_error(&e, "device.l1", "invalid type");
    assert!(e.errors[0].fix.contains("l1 = 0.1"), "{e}");
    let e = device_errors("observer_gain = [60.0, 60.0]\n");
    assert_field_error(&e, "observer_gain", "");
}

#[test]
fn invalid_values_name_the_field() {
    for (text, field, what) in [
        ("tau_max = -0.5\n", "tau_max", "> 0"),
        ("[device]\nl1 = 0.0\n", "device.l1", "> 0"),
        (
            "friction_compensation = 1.5\n",
            "friction_compensation",
            "[0, 1]",
        ),
        ("l2 = 0.02\n", "l2", "s/2"),
        (
            "workspace_half_width = 0.2\n",
            "workspace_half_width",
            "reachable",
        ),
        (
            "observer_gain = [60.0, 0.0, 60.0]\n",
            "observer_gain[1]",
            "> 0",
        ),
    ] {
        let e = device_errors(text);
        assert_field_error(&e, field, what);
    }
    // The gain × period bound, when the period is known.
    let e = device_params_from_toml(
        "observer_gain = [600, 60, 60]\n",
        "my-device.toml",
        Some(0.002),
    )
    .unwrap_err();
    assert_field_error(&e, "observer_gain[0]", "< 1");
    assert!(device_params_from_toml("observer_gain = [600, 60, 60]\n", "f", Some(0.001)).is_ok());
}

#[test]
fn stray_keys_next_to_the_device_table_and_bad_toml_are_errors() {
    let e = device_errors("name = \"rig\"\n[device]\nl1 = 0.1\n");
    assert_field_error(&e, "name", "[device]");
    let e = device_errors("device = 3\n");
    assert_field_error(&e, "device", "table");
    let e = device_errors("[device]\nl1 = = 0.1\n");
    assert_field_error(&e, "line 2", "");
}

/// A scene with no `[device]` table: the wall and the box 0.04 m from it.
fn scene_text() -> String {
    format!(
        "name = \"with-device\"\n{}position = [0.04, 0.0]\n",
        crate::shared::WALL_AND_BOX_TOML
    )
}

#[test]
fn scene_device_table_overrides_the_defaults() {
    let plain = Scene::from_toml(&scene_text(), "s.toml", None).unwrap();
    assert_eq!(plain.device, None, "no [device] table: None");
    let text = format!("{}\n[device]\nm_h = 0.12\nf_c = 0.01\n", scene_text());
    let s = Scene::from_toml(&text, "s.toml", None).unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        s.device,
        Some(DeviceParams {
            m_h: 0.12,
            f_c: 0.01,
            ..DeviceParams::default()
        })
    );
    // The whole template, pasted into a scene, is the defaults.
    let s = Scene::from_toml(&format!("{}\n{}", scene_text(), template()), "s.toml", None)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(s.device, Some(DeviceParams::default()));
}

#[test]
fn scene_device_errors_are_collected_with_the_others() {
    let text = format!(
        "{}\n[world]\nrate = 500\nproximity_every = 0\n[device]\nm_h = -1\nlinks = 2\n",
        scene_text()
    );
    let e = crate::shared::scene_errors(&text);
    let shown = e.to_string();
    let fields: Vec<&str> = e.errors.iter().map(|x| x.field.as_str()).collect();
    assert!(fields.contains(&"world.proximity_every"), "{shown}");
    assert!(fields.contains(&"device.links"), "{shown}");
    // The invalid value is reported in the same pass as the unknown field, with the default as fix.
    assert!(
        e.errors.iter().any(|x| x.field == "device.m_h"
            && x.message.contains("> 0")
            && x.fix.contains("0.08")),
        "{shown}"
    );
    // The scene's rate bounds the observer gain.
    let text = format!(
        "{}\n[world]\nrate = 100\n[device]\nobserver_gain = [200, 60, 60]\n",
        scene_text()
    );
    let e = crate::shared::scene_errors(&text);
    assert!(
        e.errors
            .iter()
            .any(|x| x.field == "device.observer_gain[0]"),
        "{e}"
    );
    assert!(Scene::from_toml(&text, "s.toml", Some(1000.0)).is_ok());
}
