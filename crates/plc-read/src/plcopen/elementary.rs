//! The elementary types of IEC 61131-3 (6.4.2, Table 10) as the reader sees them: the model's
//! own ([`MODEL_ELEMENTARY`]) and those it lacks with the model type each is read as
//! ([`MAPPED`]); whether a type name or a TC6 type tag is elementary, and its model type.
//!
//! Plain tables and lookups, below every module that reads a type (`interface`,
//! `data_types`, `black_box`); the notes about mapped variables are `interface`'s.

/// The elementary types of IEC 61131-3 (6.4.2, Table 10) the model lacks, and the model's type
/// each is read as: dates and times of day as DINT, LTIME as TIME; strings as DINT (a
/// stand-in: analysis only). docs/plcopen.md says what `run` computes differently.
pub(super) const MAPPED: &[(&str, &str)] = &[
    ("LTIME", "TIME"),
    ("DATE", "DINT"),
    ("TOD", "DINT"),
    ("TIME_OF_DAY", "DINT"),
    ("DT", "DINT"),
    ("DATE_AND_TIME", "DINT"),
    ("string", "STRING"),
    ("wstring", "DINT"),
    ("WSTRING", "DINT"),
];

/// The elementary types the model has.
pub(super) const MODEL_ELEMENTARY: &[&str] = &[
    "BOOL", "SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "REAL", "LREAL",
    "BYTE", "WORD", "DWORD", "LWORD", "TIME", "STRING",
];

/// True when a TC6 type element's tag is an elementary type (the model's or a mapped one).
pub(super) fn is_elementary_tag(tag: &str) -> bool {
    MODEL_ELEMENTARY.contains(&tag) || MAPPED.iter().any(|(f, _)| *f == tag)
}

/// True when a declared type (as the reader writes it into the syntax) is elementary, not a
/// function block type.
pub(super) fn is_elementary(ty: &str) -> bool {
    MODEL_ELEMENTARY.contains(&ty)
}

/// The model type IEC elementary type `t` is read as (`None`: not an elementary type); a
/// string as its stand-in DINT.
pub(super) fn model_type_of(t: &str) -> Option<&'static str> {
    if let Some(m) = MODEL_ELEMENTARY.iter().find(|m| **m == t) {
        return Some(m);
    }
    MAPPED.iter().find(|(f, _)| *f == t).map(|(_, m)| *m)
}
