//! Hand-written PLCopen TC6 XML for tests: a project around one body, and its elements.
#![allow(dead_code)]

pub const NS: &str = "http://www.plcopen.org/xml/tc6_0201";

/// A project with one program `P` (its variables: `(class, name, type)`) and an LD body.
pub fn project(vars: &[(&str, &str, &str)], ld: &str) -> String {
    project_in("LD", vars, ld)
}

/// [`project`] with a body in `lang` (`LD`, `FBD`).
pub fn project_in(lang: &str, vars: &[(&str, &str, &str)], body: &str) -> String {
    let mut lists = String::new();
    for class in ["inputVars", "outputVars", "localVars"] {
        let vs: Vec<String> = vars
            .iter()
            .filter(|v| v.0 == class)
            .map(|(_, n, t)| {
                let ty = if ["BOOL", "INT", "DINT", "REAL", "TIME"].contains(t) {
                    format!("<{t}/>")
                } else {
                    format!("<derived name=\"{t}\"/>")
                };
                format!("<variable name=\"{n}\"><type>{ty}</type></variable>")
            })
            .collect();
        if !vs.is_empty() {
            lists.push_str(&format!("<{class}>{}</{class}>\n", vs.concat()));
        }
    }
    format!(
        r#"<?xml version="1.0" encoding="utf-8"?>
<project xmlns="{NS}">
  <fileHeader companyName="t" productName="t" productVersion="1" creationDateTime="2024-01-01T00:00:00"/>
  <contentHeader name="t"><coordinateInfo><fbd><scaling x="1" y="1"/></fbd><ld><scaling x="1" y="1"/></ld><sfc><scaling x="1" y="1"/></sfc></coordinateInfo></contentHeader>
  <types><dataTypes/><pous>
    <pou name="P" pouType="program">
      <interface>
{lists}      </interface>
      <body><{lang}>
{body}
      </{lang}></body>
    </pou>
  </pous></types>
  <instances><configurations/></instances>
</project>
"#
    )
}

pub fn conn(from: &[u32]) -> String {
    let c: Vec<String> = from
        .iter()
        .map(|r| format!("<connection refLocalId=\"{r}\"/>"))
        .collect();
    format!("<connectionPointIn>{}</connectionPointIn>", c.concat())
}

pub fn rail(id: u32) -> String {
    format!("<leftPowerRail localId=\"{id}\"><connectionPointOut formalParameter=\"\"/></leftPowerRail>")
}

pub fn contact(id: u32, var: &str, from: &[u32], attrs: &str) -> String {
    format!(
        "<contact localId=\"{id}\" {attrs}>{}<connectionPointOut/><variable>{var}</variable></contact>",
        conn(from)
    )
}

pub fn coil(id: u32, var: &str, from: &[u32], attrs: &str) -> String {
    format!(
        "<coil localId=\"{id}\" {attrs}>{}<connectionPointOut/><variable>{var}</variable></coil>",
        conn(from)
    )
}

pub fn in_var(id: u32, expr: &str) -> String {
    format!("<inVariable localId=\"{id}\"><connectionPointOut/><expression>{expr}</expression></inVariable>")
}

/// An FBD block: `(pin, sources)` inputs (a source `(localId, Some(pin))`), output pin names.
pub fn block(
    id: u32,
    ty: &str,
    instance: Option<&str>,
    inputs: &[(&str, &[(u32, Option<&str>)])],
    outputs: &[&str],
) -> String {
    let ins: Vec<String> = inputs
        .iter()
        .map(|(pin, from)| {
            let c: Vec<String> = from
                .iter()
                .map(|(r, p)| match p {
                    Some(p) => format!("<connection refLocalId=\"{r}\" formalParameter=\"{p}\"/>"),
                    None => format!("<connection refLocalId=\"{r}\"/>"),
                })
                .collect();
            format!(
                "<variable formalParameter=\"{pin}\"><connectionPointIn>{}</connectionPointIn></variable>",
                c.concat()
            )
        })
        .collect();
    let outs: Vec<String> = outputs
        .iter()
        .map(|p| format!("<variable formalParameter=\"{p}\"><connectionPointOut/></variable>"))
        .collect();
    let inst = instance.map_or(String::new(), |i| format!(" instanceName=\"{i}\""));
    format!(
        "<block localId=\"{id}\" typeName=\"{ty}\"{inst}><inputVariables>{}</inputVariables><inOutVariables/><outputVariables>{}</outputVariables></block>",
        ins.concat(),
        outs.concat()
    )
}

/// An out variable (or, with `tag`, an in-out variable) fed by `(localId, pin)`.
pub fn var_in(tag: &str, id: u32, expr: &str, from: (u32, Option<&str>)) -> String {
    let c = match from.1 {
        Some(p) => format!(
            "<connection refLocalId=\"{}\" formalParameter=\"{p}\"/>",
            from.0
        ),
        None => format!("<connection refLocalId=\"{}\"/>", from.0),
    };
    let out = if tag == "inOutVariable" {
        "<connectionPointOut/>"
    } else {
        ""
    };
    format!("<{tag} localId=\"{id}\"><connectionPointIn>{c}</connectionPointIn>{out}<expression>{expr}</expression></{tag}>")
}
