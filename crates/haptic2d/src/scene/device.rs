//! Device parameters from TOML: a scene file's `[device]` table, or a device file (`haptic2d run
//! --device-file`). Any subset of [`DeviceParams`] fields overrides the spec defaults (§10.2); unknown
//! fields, values of the wrong type and values that fail [`DeviceParams::validate`] are errors naming
//! the field.

use super::{SceneError, SceneErrors};
use crate::device::DeviceParams;

/// Where the template listing every field lives (repository root), named in fixes.
pub const DEVICE_TEMPLATE: &str = "devices/twin-pantograph.toml";

/// The spec defaults as a TOML table: the field names and their default values.
fn defaults_table() -> toml::Table {
    match toml::Value::try_from(DeviceParams::default()) {
        Ok(toml::Value::Table(t)) => t,
        // DeviceParams is a struct of numbers: it always serializes to a table.
        _ => toml::Table::new(),
    }
}

/// `name` without an index or a `/second` part: `observer_gain[0]` → `observer_gain`.
fn base_name(name: &str) -> &str {
    let end = name.find(['[', '/']).unwrap_or(name.len());
    &name[..end]
}

/// "in m, e.g. l2 = 0.13 (the spec default; remove the line to use it)".
fn example(name: &str, defaults: &toml::Table) -> String {
    let base = base_name(name);
    let unit = match DeviceParams::unit_of(base) {
        Some("-") | None => String::new(),
        Some(u) => format!(" in {u}"),
    };
    match defaults.get(base) {
        Some(v) => format!(
            "give {base}{unit}, e.g. {base} = {v} (the spec default; remove the line to use it)"
        ),
        None => format!("see {DEVICE_TEMPLATE} for every field, its default and unit"),
    }
}

/// Reads device parameters from `table`, whose fields are reported as `{prefix}{name}` (`prefix` is
/// `"device."` for a `[device]` table, `""` for top-level keys). When `dt` (s) is given, also checks
/// the parameters that depend on the sample period. Pushes every problem to `errs`; returns the
/// parameters only when there was none.
pub(super) fn device_from_table(
    table: &toml::Table,
    prefix: &str,
    dt: Option<f64>,
    errs: &mut Vec<SceneError>,
) -> Option<DeviceParams> {
    let defaults = defaults_table();
    let before = errs.len();
    // The fields that are known and of the right type; the values are checked on them even when
    // other fields are wrong, so that one pass reports every problem.
    let mut good = toml::Table::new();
    for (key, value) in table {
        if !defaults.contains_key(key) {
            let names: Vec<&str> = DeviceParams::FIELDS.iter().map(|(n, _)| *n).collect();
            errs.push(SceneError::new(
                format!("{prefix}{key}"),
                "unknown device parameter",
                format!(
                    "use one of: {} (every field, with its default and unit, is in {DEVICE_TEMPLATE})",
                    names.join(", ")
                ),
            ));
            continue;
        }
        // Each field on its own, so that a wrong type names that field.
        let mut one = toml::Table::new();
        one.insert(key.clone(), value.clone());
        match toml::Value::Table(one).try_into::<DeviceParams>() {
            Ok(_) => {
                good.insert(key.clone(), value.clone());
            }
            Err(e) => errs.push(SceneError::new(
                format!("{prefix}{key}"),
                e.message().trim_end().to_string(),
                example(key, &defaults),
            )),
        }
    }
    let params = match toml::Value::Table(good).try_into::<DeviceParams>() {
        Ok(p) => p,
        Err(e) => {
            errs.push(SceneError::new(
                prefix.trim_end_matches('.').to_string(),
                e.message().trim_end().to_string(),
                format!("compare with {DEVICE_TEMPLATE}"),
            ));
            return None;
        }
    };
    let checked = params
        .validate()
        .and_then(|()| dt.map_or(Ok(()), |dt| params.validate_for_period(dt)));
    if let Err(msg) = checked {
        errs.push(validation_error(&msg, prefix, &defaults));
        return None;
    }
    (errs.len() == before).then_some(params)
}

/// Turns a [`DeviceParams::validate`] message (`device.NAME what`) into an error on `{prefix}NAME`.
fn validation_error(msg: &str, prefix: &str, defaults: &toml::Table) -> SceneError {
    let body = msg.strip_prefix("device.").unwrap_or(msg);
    let end = body.find([' ', ':']).unwrap_or(body.len());
    let name = &body[..end];
    let rest = body[end..].trim_start_matches(':').trim();
    let message = if rest.starts_with('=') || rest.starts_with('(') {
        format!("{name} {rest}")
    } else {
        rest.to_string()
    };
    let fix = if rest.contains("singularity") {
        "shrink workspace_half_width, move the workspace centre (workspace_center_x, workspace_center_y), change the link lengths, or lower min_singularity_margin (spec defaults in devices/twin-pantograph.toml)".to_string()
    } else if rest.contains("not reachable") {
        "shrink workspace_half_width, move the workspace centre (workspace_center_x, workspace_center_y) within reach, or lengthen l1/l2 (spec defaults in devices/twin-pantograph.toml)".to_string()
    } else if name == "l2" && rest.contains("s/2") {
        "make l2 longer than s/2, or bring the motor axes closer (smaller s)".to_string()
    } else if base_name(name) == "observer_gain" {
        "lower observer_gain or raise the control rate (--rate, world.rate) so that gain × period < 1"
            .to_string()
    } else {
        example(name, defaults)
    };
    SceneError::new(format!("{prefix}{name}"), message, fix)
}

/// Parses a device file: either top-level [`DeviceParams`] keys, or one `[device]` table (the form a
/// scene file uses, so a scene's table can be copied out as is). `source` names the file in
/// messages. When `dt` (s) is given, the parameters that depend on the sample period are checked
/// too. Every problem is reported with the field and the fix; nothing panics.
pub fn device_params_from_toml(
    text: &str,
    source: &str,
    dt: Option<f64>,
) -> Result<DeviceParams, SceneErrors> {
    let fix = format!("check the TOML syntax against {DEVICE_TEMPLATE}");
    let table: toml::Table = SceneErrors::parse(text, source, fix)?;
    let mut errs = Vec::new();
    let params = match table.get("device") {
        Some(toml::Value::Table(device)) => {
            for key in table.keys().filter(|k| *k != "device") {
                errs.push(SceneError::new(
                    key.clone(),
                    "unexpected next to the [device] table",
                    "a device file holds either device parameters at the top level or one [device] table: move it into [device] or remove it",
                ));
            }
            device_from_table(device, "device.", dt, &mut errs)
        }
        Some(other) => {
            errs.push(SceneError::new(
                "device",
                format!("expected a [device] table, got {other}"),
                format!("write the parameters under a [device] header, as in {DEVICE_TEMPLATE}"),
            ));
            None
        }
        None => device_from_table(&table, "", dt, &mut errs),
    };
    match params {
        Some(p) if errs.is_empty() => Ok(p),
        _ => Err(SceneErrors::new(source, errs)),
    }
}
