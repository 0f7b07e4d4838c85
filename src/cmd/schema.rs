//! `plc-deps schema`: the JSON Schema of the program format (docs/format.md).

/// The JSON Schema of the program format (`plc-deps schema`).
pub const PROGRAM_SCHEMA: &str = include_str!("../../schema/program.schema.json");
