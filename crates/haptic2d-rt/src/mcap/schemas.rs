//! The JSON Schemas of the MCAP channels other than `/haptic2d/tick` (whose schema is generated
//! from the column table, [`tick_json_schema`](super::columns::tick_json_schema)). All channels use
//! message encoding `json` and schema encoding `jsonschema` (MCAP well-known encodings), so any MCAP
//! reader can decode them without our code. Floats are JSON numbers; the non-finite ones (JSON has
//! none) are the strings `"NaN"`, `"inf"`, `"-inf"`. Documented in docs/LOGS.md.

/// Topic of the tick records (one message per tick).
pub const TOPIC_TICK: &str = "/haptic2d/tick";
/// Topic of the bodies' poses and twists (one message per tick or world sample).
pub const TOPIC_BODIES: &str = "/haptic2d/bodies";
/// Topic of the contact records (one message per tick or world sample).
pub const TOPIC_CONTACTS: &str = "/haptic2d/contacts";
/// Topic of the energy ledger (one message per tick or world sample).
pub const TOPIC_ENERGY: &str = "/haptic2d/energy";
/// Topic of the run's description: scene and device files (one message, at the first tick).
pub const TOPIC_SCENE: &str = "/haptic2d/scene";
/// Topic of Foxglove `SceneUpdate`s drawing the bodies and contact forces (decimated).
pub const TOPIC_SCENE_UPDATE: &str = "/haptic2d/scene_update";

/// Topic of Foxglove `FrameTransforms` placing each body (`body/NAME`) and, in a run, the device
/// handle (`device`) and the slave (`slave`) in the `world` frame (decimated like the scene).
pub const TOPIC_TF: &str = "/haptic2d/tf";

/// Schema name of `/haptic2d/tick`.
pub const SCHEMA_TICK: &str = "haptic2d.Tick";
/// Schema name of `/haptic2d/bodies`.
pub const SCHEMA_BODIES: &str = "haptic2d.Bodies";
/// Schema name of `/haptic2d/contacts`.
pub const SCHEMA_CONTACTS: &str = "haptic2d.Contacts";
/// Schema name of `/haptic2d/energy`.
pub const SCHEMA_ENERGY: &str = "haptic2d.Energy";
/// Schema name of `/haptic2d/scene`.
pub const SCHEMA_SCENE: &str = "haptic2d.Scene";
/// Foxglove's schema name (its 3-D panel recognises it by name).
pub const SCHEMA_SCENE_UPDATE: &str = "foxglove.SceneUpdate";

/// Foxglove's schema name of a list of frame transforms (its 3-D panel recognises it by name).
pub const SCHEMA_TF: &str = "foxglove.FrameTransforms";

/// `/haptic2d/bodies`.
pub const BODIES_SCHEMA: &str = r#"{"$schema":"https://json-schema.org/draft/2020-12/schema","title":"haptic2d.Bodies","description":"Poses and twists of the world's bodies after the step","type":"object","properties":{"t":{"type":["number","string"],"description":"world time (s)"},"count":{"type":"integer","description":"bodies in the world (the array keeps at most 32)"},"bodies":{"type":"array","items":{"type":"object","properties":{"name":{"type":"string"},"x":{"type":["number","string"],"description":"m"},"y":{"type":["number","string"],"description":"m"},"theta":{"type":["number","string"],"description":"rad"},"vx":{"type":["number","string"],"description":"m/s"},"vy":{"type":["number","string"],"description":"m/s"},"omega":{"type":["number","string"],"description":"rad/s"}}}}}}"#;

/// `/haptic2d/contacts`.
pub const CONTACTS_SCHEMA: &str = r#"{"$schema":"https://json-schema.org/draft/2020-12/schema","title":"haptic2d.Contacts","description":"Contact records (vertex of body_a on an edge of body_b) after the step","type":"object","properties":{"t":{"type":["number","string"],"description":"world time (s)"},"count":{"type":"integer","description":"contact records in the world (the array keeps at most 32)"},"contacts":{"type":"array","items":{"type":"object","properties":{"body_a":{"type":"string","description":"body owning the vertex"},"body_b":{"type":"string","description":"body owning the edge"},"state":{"enum":["colliding","continuous"]},"x":{"type":["number","string"],"description":"vertex position x (m, world)"},"y":{"type":["number","string"],"description":"vertex position y (m, world)"},"nx":{"type":["number","string"],"description":"outward edge normal x"},"ny":{"type":["number","string"],"description":"outward edge normal y"},"penetration":{"type":["number","string"],"description":"-d_k (m, positive inside)"},"f_n":{"type":["number","string"],"description":"normal force (N)"},"f_t":{"type":["number","string"],"description":"friction force on body_a along the edge tangent (N)"},"slip":{"type":["number","string"],"description":"tangential slip velocity (m/s)"}}}}}}"#;

/// `/haptic2d/energy`.
pub const ENERGY_SCHEMA: &str = r#"{"$schema":"https://json-schema.org/draft/2020-12/schema","title":"haptic2d.Energy","description":"The world's energy ledger after the step (J)","type":"object","properties":{"t":{"type":["number","string"],"description":"world time (s)"},"kinetic":{"type":["number","string"],"description":"kinetic energy of the dynamic bodies (J)"},"stored":{"type":["number","string"],"description":"energy stored in contact and friction springs (J)"},"applied_work":{"type":["number","string"],"description":"cumulative work of loads and drives (J)"},"initial":{"type":["number","string"],"description":"kinetic + stored at the start (J)"},"impact_loss":{"type":["number","string"],"description":"kinetic energy removed by impacts so far (J)"},"excess":{"type":["number","string"],"description":"(kinetic + stored) - (initial + applied_work) (J); > 0 means generated energy"}}}"#;

/// `/haptic2d/scene`.
pub const SCENE_SCHEMA: &str = r#"{"$schema":"https://json-schema.org/draft/2020-12/schema","title":"haptic2d.Scene","description":"The run's description: scene and device files as text, rate and settings; the same strings are in the metadata record haptic2d.scene","type":"object","additionalProperties":{"type":"string"}}"#;

/// Foxglove's `SceneUpdate`, the subset of the published JSON Schema we write (entities with line
/// primitives; the other primitive arrays are present and empty).
pub const SCENE_UPDATE_SCHEMA: &str = r##"{"$schema":"https://json-schema.org/draft/2020-12/schema","$comment":"foxglove.SceneUpdate (subset used by haptic2d)","title":"foxglove.SceneUpdate","description":"An update to the entities displayed in a 3D scene","type":"object","properties":{"deletions":{"type":"array","items":{"type":"object","properties":{"timestamp":{"$ref":"#/$defs/time"},"type":{"type":"integer","description":"0 MATCHING_ID, 1 ALL"},"id":{"type":"string"}}}},"entities":{"type":"array","items":{"type":"object","properties":{"timestamp":{"$ref":"#/$defs/time"},"frame_id":{"type":"string"},"id":{"type":"string"},"lifetime":{"$ref":"#/$defs/duration"},"frame_locked":{"type":"boolean"},"metadata":{"type":"array","items":{"type":"object","properties":{"key":{"type":"string"},"value":{"type":"string"}}}},"arrows":{"type":"array"},"cubes":{"type":"array"},"spheres":{"type":"array"},"cylinders":{"type":"array"},"lines":{"type":"array","items":{"type":"object","properties":{"type":{"type":"integer","description":"0 LINE_STRIP, 1 LINE_LOOP, 2 LINE_LIST"},"pose":{"$ref":"#/$defs/pose"},"thickness":{"type":"number"},"scale_invariant":{"type":"boolean"},"points":{"type":"array","items":{"$ref":"#/$defs/vector3"}},"color":{"$ref":"#/$defs/color"},"colors":{"type":"array","items":{"$ref":"#/$defs/color"}},"indices":{"type":"array","items":{"type":"integer"}}}}},"triangles":{"type":"array"},"texts":{"type":"array"},"models":{"type":"array"}}}}},"$defs":{"time":{"type":"object","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}}},"duration":{"type":"object","properties":{"sec":{"type":"integer"},"nsec":{"type":"integer","minimum":0,"maximum":999999999}}},"vector3":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}}},"quaternion":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}}},"pose":{"type":"object","properties":{"position":{"$ref":"#/$defs/vector3"},"orientation":{"$ref":"#/$defs/quaternion"}}},"color":{"type":"object","properties":{"r":{"type":"number"},"g":{"type":"number"},"b":{"type":"number"},"a":{"type":"number"}}}}}"##;

/// Foxglove's `FrameTransforms` (JSON Schema after Foxglove's published one,
/// `schemas/jsonschema/FrameTransforms.json` of foxglove/foxglove-sdk: `transforms`, each a
/// `FrameTransform` with `timestamp`, `parent_frame_id`, `child_frame_id`, `translation` (Vector3),
/// `rotation` (Quaternion), all required; descriptions shortened;
/// <https://docs.foxglove.dev/docs/visualization/message-schemas/frame-transform/>).
pub const TF_SCHEMA: &str = r##"{"$schema":"https://json-schema.org/draft/2020-12/schema","title":"foxglove.FrameTransforms","description":"An array of FrameTransform messages","type":"object","properties":{"transforms":{"type":"array","items":{"title":"foxglove.FrameTransform","description":"A transform between two reference frames in 3D space","type":"object","properties":{"timestamp":{"type":"object","title":"time","properties":{"sec":{"type":"integer","minimum":0},"nsec":{"type":"integer","minimum":0,"maximum":999999999}},"description":"Timestamp of transform"},"parent_frame_id":{"type":"string","description":"Name of the parent frame"},"child_frame_id":{"type":"string","description":"Name of the child frame"},"translation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"}},"required":["x","y","z"],"description":"Translation component of the transform"},"rotation":{"type":"object","properties":{"x":{"type":"number"},"y":{"type":"number"},"z":{"type":"number"},"w":{"type":"number"}},"required":["x","y","z","w"],"description":"Rotation component of the transform"}},"required":["timestamp","parent_frame_id","child_frame_id","translation","rotation"]}}},"required":["transforms"]}"##;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_schema_is_json() {
        for s in [
            BODIES_SCHEMA,
            CONTACTS_SCHEMA,
            ENERGY_SCHEMA,
            SCENE_SCHEMA,
            SCENE_UPDATE_SCHEMA,
            TF_SCHEMA,
        ] {
            let v: serde_json::Value = serde_json::from_str(s).unwrap();
            assert_eq!(v["type"], "object");
        }
    }
}
