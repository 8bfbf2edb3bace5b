//! JSON encoders of the channels' messages, into a caller's reused buffer (appending). Shared by
//! the MCAP writer and the Foxglove live server, so a live view and a recording carry the same
//! bytes. Floats: [`write_json_f64`].

use crate::mcap::columns::{tick_row, write_json_f64, write_key, write_row_members, TickRow};
use crate::mcap::record::{LoggedTick, WorldSample};
use std::io::Write;

/// A body's name and outline, for the names in the messages and the `SceneUpdate` drawing.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyGeom {
    /// Body name.
    pub name: String,
    /// True for a dynamic body.
    pub dynamic: bool,
    /// The body's collider polygons, body frame (m), counter-clockwise.
    pub outlines: Vec<Vec<[f64; 2]>>,
}

/// Scale of the contact-force lines drawn in the `SceneUpdate` (m per N): 1 N draws 1 mm.
pub const FORCE_LINE_M_PER_N: f64 = 1e-3;

/// Writes a `/haptic2d/tick` message of the present cells of `row`.
pub fn encode_tick_row(b: &mut Vec<u8>, row: &TickRow) -> std::io::Result<()> {
    b.push(b'{');
    write_row_members(b, row, true)?;
    b.push(b'}');
    Ok(())
}

/// Writes the `/haptic2d/tick` message of `t`.
pub fn encode_tick(b: &mut Vec<u8>, t: &LoggedTick) -> std::io::Result<()> {
    encode_tick_row(
        b,
        &tick_row(t.index, t.deadline_ns, t.lateness_ns, &t.q, &t.rec),
    )
}

/// Writes a `/haptic2d/bodies` message (`names`: the bodies' names as JSON strings).
pub fn encode_bodies(b: &mut Vec<u8>, names: &[String], s: &WorldSample) -> std::io::Result<()> {
    b.extend_from_slice(b"{\"t\":");
    write_json_f64(b, s.t)?;
    write!(b, ",\"count\":{},\"bodies\":[", s.body_count)?;
    for (i, body) in s.bodies().iter().enumerate() {
        if i > 0 {
            b.push(b',');
        }
        match names.get(i) {
            Some(n) => write!(b, "{{\"name\":{n}")?,
            None => write!(b, "{{\"name\":\"body{i}\"")?,
        }
        write_fields(b, ["x", "y", "theta"].into_iter().zip(body.pose))?;
        write_fields(b, ["vx", "vy", "omega"].into_iter().zip(body.twist))?;
        b.push(b'}');
    }
    b.extend_from_slice(b"]}");
    Ok(())
}

/// Writes `,"key":value` for each `(key, value)` of `fields` (values as [`write_json_f64`]
/// writes them).
fn write_fields<'a>(
    b: &mut Vec<u8>,
    fields: impl IntoIterator<Item = (&'a str, f64)>,
) -> std::io::Result<()> {
    for (k, v) in fields {
        b.push(b',');
        write_key(b, k)?;
        write_json_f64(b, v)?;
    }
    Ok(())
}

/// Writes a `/haptic2d/contacts` message (`names`: the bodies' names as JSON strings).
pub fn encode_contacts(b: &mut Vec<u8>, names: &[String], s: &WorldSample) -> std::io::Result<()> {
    let name = |i: u32| {
        names
            .get(i as usize)
            .cloned()
            .unwrap_or_else(|| format!("\"body{i}\""))
    };
    b.extend_from_slice(b"{\"t\":");
    write_json_f64(b, s.t)?;
    write!(b, ",\"count\":{},\"contacts\":[", s.contact_count)?;
    for (i, c) in s.contacts().iter().enumerate() {
        if i > 0 {
            b.push(b',');
        }
        write!(
            b,
            "{{\"body_a\":{},\"body_b\":{},\"state\":\"{}\"",
            name(c.body_a),
            name(c.body_b),
            if c.colliding {
                "colliding"
            } else {
                "continuous"
            }
        )?;
        write_fields(
            b,
            [
                ("x", c.point[0]),
                ("y", c.point[1]),
                ("nx", c.normal[0]),
                ("ny", c.normal[1]),
                ("penetration", c.penetration),
                ("f_n", c.f_n),
                ("f_t", c.f_t),
                ("slip", c.slip),
            ],
        )?;
        b.push(b'}');
    }
    b.extend_from_slice(b"]}");
    Ok(())
}

/// Writes a `/haptic2d/energy` message.
pub fn encode_energy(b: &mut Vec<u8>, s: &WorldSample) -> std::io::Result<()> {
    let l = &s.ledger;
    b.extend_from_slice(b"{\"t\":");
    write_json_f64(b, s.t)?;
    write_fields(
        b,
        [
            ("kinetic", l.kinetic),
            ("stored", l.stored),
            ("applied_work", l.applied_work),
            ("initial", l.initial),
            ("impact_loss", l.impact_loss),
            ("excess", l.excess()),
        ],
    )?;
    b.push(b'}');
    Ok(())
}

/// Writes a Foxglove `SceneUpdate` (JSON): one entity per body (its outlines as `LINE_LOOP`s, posed
/// at the body's pose; dynamic bodies blue, fixed grey) and one `contacts` entity with a line per
/// contact along the normal, `f_n · FORCE_LINE_M_PER_N` long. Planar: z = 0, rotation about z.
pub fn encode_scene_update<B: Write>(
    b: &mut B,
    geom: &[BodyGeom],
    names: &[String],
    s: &WorldSample,
    log_time: u64,
) -> std::io::Result<()> {
    let (sec, nsec) = (log_time / 1_000_000_000, log_time % 1_000_000_000);
    let empty = "\"arrows\":[],\"cubes\":[],\"spheres\":[],\"cylinders\":[],\"triangles\":[],\"texts\":[],\"models\":[]";
    b.write_all(b"{\"deletions\":[],\"entities\":[")?;
    let mut first = true;
    for (i, body) in s.bodies().iter().enumerate() {
        let Some(g) = geom.get(i) else { continue };
        if !first {
            b.write_all(b",")?;
        }
        first = false;
        let name = names.get(i).map_or("\"?\"", |n| n.as_str());
        // Rotation by θ about z as a unit quaternion: (0, 0, sin(θ/2), cos(θ/2)).
        let half = 0.5 * body.pose[2];
        let (qz, qw) = (half.sin(), half.cos());
        write!(
            b,
            "{{\"timestamp\":{{\"sec\":{sec},\"nsec\":{nsec}}},\"frame_id\":\"world\",\"id\":{name},\"lifetime\":{{\"sec\":0,\"nsec\":0}},\"frame_locked\":false,\"metadata\":[],{empty},\"lines\":["
        )?;
        let color = if g.dynamic {
            "{\"r\":0.2,\"g\":0.45,\"b\":0.9,\"a\":1}"
        } else {
            "{\"r\":0.55,\"g\":0.55,\"b\":0.55,\"a\":1}"
        };
        for (k, outline) in g.outlines.iter().enumerate() {
            if k > 0 {
                b.write_all(b",")?;
            }
            b.write_all(b"{\"type\":1,\"pose\":{\"position\":{\"x\":")?;
            write_json_f64(b, body.pose[0])?;
            b.write_all(b",\"y\":")?;
            write_json_f64(b, body.pose[1])?;
            b.write_all(b",\"z\":0},\"orientation\":{\"x\":0,\"y\":0,\"z\":")?;
            write_json_f64(b, qz)?;
            b.write_all(b",\"w\":")?;
            write_json_f64(b, qw)?;
            b.write_all(b"}},\"thickness\":0.002,\"scale_invariant\":false,\"points\":[")?;
            write_points(b, outline.iter().copied())?;
            write!(b, "],\"color\":{color},\"colors\":[],\"indices\":[]}}")?;
        }
        b.write_all(b"]}")?;
    }
    if !first {
        b.write_all(b",")?;
    }
    write!(
        b,
        "{{\"timestamp\":{{\"sec\":{sec},\"nsec\":{nsec}}},\"frame_id\":\"world\",\"id\":\"contacts\",\"lifetime\":{{\"sec\":0,\"nsec\":0}},\"frame_locked\":false,\"metadata\":[],{empty},\"lines\":[{{\"type\":2,\"pose\":{{\"position\":{{\"x\":0,\"y\":0,\"z\":0}},\"orientation\":{{\"x\":0,\"y\":0,\"z\":0,\"w\":1}}}},\"thickness\":0.002,\"scale_invariant\":false,\"points\":["
    )?;
    write_points(
        b,
        s.contacts().iter().flat_map(|c| {
            let len = c.f_n * FORCE_LINE_M_PER_N;
            let tip = [
                c.point[0] + c.normal[0] * len,
                c.point[1] + c.normal[1] * len,
            ];
            [c.point, tip]
        }),
    )?;
    b.write_all(
        b"],\"color\":{\"r\":0.9,\"g\":0.2,\"b\":0.2,\"a\":1},\"colors\":[],\"indices\":[]}]}]}",
    )?;
    Ok(())
}

/// Writes `points` as comma-separated Foxglove `Point3`s in the plane, `{"x":…,"y":…,"z":0}`.
fn write_points<B: Write>(
    b: &mut B,
    points: impl IntoIterator<Item = [f64; 2]>,
) -> std::io::Result<()> {
    for (j, p) in points.into_iter().enumerate() {
        if j > 0 {
            b.write_all(b",")?;
        }
        b.write_all(b"{\"x\":")?;
        write_json_f64(b, p[0])?;
        b.write_all(b",\"y\":")?;
        write_json_f64(b, p[1])?;
        b.write_all(b",\"z\":0}")?;
    }
    Ok(())
}

/// Writes one `FrameTransform` (JSON object) of frame `child` in `world` at the planar pose
/// `[x, y, θ]` (m, m, rad): translation `(x, y, 0)`, rotation θ about z.
fn write_transform<B: Write>(
    b: &mut B,
    sec: u64,
    nsec: u64,
    child: &str,
    pose: [f64; 3],
) -> std::io::Result<()> {
    let half = 0.5 * pose[2];
    write!(
        b,
        "{{\"timestamp\":{{\"sec\":{sec},\"nsec\":{nsec}}},\"parent_frame_id\":\"world\",\"child_frame_id\":{child},\"translation\":{{\"x\":"
    )?;
    write_json_f64(b, pose[0])?;
    b.write_all(b",\"y\":")?;
    write_json_f64(b, pose[1])?;
    b.write_all(b",\"z\":0},\"rotation\":{\"x\":0,\"y\":0,\"z\":")?;
    write_json_f64(b, half.sin())?;
    b.write_all(b",\"w\":")?;
    write_json_f64(b, half.cos())?;
    b.write_all(b"}}")
}

/// Writes a Foxglove `FrameTransforms` (JSON, `/haptic2d/tf`): the frame `body/NAME` of every body
/// kept in the sample, and — for a haptic tick (`tick` given) — `device` at the handle pose and
/// `slave` at the slave pose, all children of `world`. Poses are planar: `(x, y, 0)` and a rotation
/// by θ about z (quaternion `(0, 0, sin θ/2, cos θ/2)`). `names`: the bodies' names as JSON
/// strings. A frame whose pose is not finite (a device that sent NaN) is left out of the message:
/// Foxglove's schema wants numbers there, and a frame has no place to be drawn.
pub fn encode_frame_transforms<B: Write>(
    b: &mut B,
    names: &[String],
    s: &WorldSample,
    tick: Option<&haptic2d::haptic::TickRecord>,
    log_time: u64,
) -> std::io::Result<()> {
    let (sec, nsec) = (log_time / 1_000_000_000, log_time % 1_000_000_000);
    b.write_all(b"{\"transforms\":[")?;
    let mut first = true;
    let finite = |p: &[f64; 3]| p.iter().all(|v| v.is_finite());
    for (i, body) in s.bodies().iter().enumerate() {
        if !finite(&body.pose) {
            continue;
        }
        if !first {
            b.write_all(b",")?;
        }
        first = false;
        // `names` are JSON strings (quoted, escaped): the frame id is `"body/` + their inside.
        let child = match names.get(i) {
            Some(n) if n.len() >= 2 => format!("\"body/{}", &n[1..]),
            _ => format!("\"body/body{i}\""),
        };
        write_transform(b, sec, nsec, &child, body.pose)?;
    }
    if let Some(r) = tick {
        for (child, pose) in [("\"device\"", r.x_m), ("\"slave\"", r.x_s)] {
            if !finite(&pose) {
                continue;
            }
            if !first {
                b.write_all(b",")?;
            }
            first = false;
            write_transform(b, sec, nsec, child, pose)?;
        }
    }
    b.write_all(b"]}")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mcap::schemas::TF_SCHEMA;
    use haptic2d::haptic::TickRecord;

    #[test]
    fn frame_transforms_rotate_about_z_and_leave_out_a_non_finite_pose() {
        let mut s = WorldSample {
            body_count: 2,
            ..WorldSample::default()
        };
        s.bodies[0].pose = [0.1, -0.2, std::f64::consts::FRAC_PI_2];
        s.bodies[1].pose = [f64::NAN, 0.0, 0.0];
        let rec = TickRecord {
            x_m: [0.3, 0.4, 0.0],
            x_s: [0.0, f64::INFINITY, 0.0],
            ..TickRecord::default()
        };
        let names = vec!["\"box\"".to_string(), "\"bad\"".to_string()];
        let mut b = Vec::new();
        encode_frame_transforms(&mut b, &names, &s, Some(&rec), 1_700_000_000_123_456_789).unwrap();
        let v: serde_json::Value = serde_json::from_slice(&b).unwrap();
        let t = v["transforms"].as_array().unwrap();
        // body/bad and slave have non-finite poses: left out.
        let frames: Vec<&str> = t
            .iter()
            .map(|x| x["child_frame_id"].as_str().unwrap())
            .collect();
        assert_eq!(frames, ["body/box", "device"]);
        let q = &t[0]["rotation"];
        let h = std::f64::consts::FRAC_1_SQRT_2; // 90° about z: (0, 0, sin 45°, cos 45°)
        assert!((q["z"].as_f64().unwrap() - h).abs() < 1e-15);
        assert!((q["w"].as_f64().unwrap() - h).abs() < 1e-15);
        assert_eq!(t[0]["timestamp"]["sec"], 1_700_000_000);
        assert_eq!(t[0]["timestamp"]["nsec"], 123_456_789);
        assert_eq!(t[1]["translation"]["x"], 0.3);
        // Every field Foxglove's schema requires is there, numbers where it wants numbers.
        let schema: serde_json::Value = serde_json::from_str(TF_SCHEMA).unwrap();
        let item = &schema["properties"]["transforms"]["items"];
        for x in t {
            for k in item["required"].as_array().unwrap() {
                assert!(x.get(k.as_str().unwrap()).is_some(), "{k} missing in {x}");
            }
            for (obj, keys) in [("translation", "xyz"), ("rotation", "xyzw")] {
                for k in keys.chars() {
                    assert!(x[obj][k.to_string()].is_number(), "{x}");
                }
            }
        }
    }
}
