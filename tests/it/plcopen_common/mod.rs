//! Hand-written PLCopen TC6 XML for tests: a project around one body, and its elements.
#![allow(dead_code)]

mod generated;
#[allow(unused_imports)]
pub(crate) use generated::{generated_ld, NS};

/// A project with one program `P` (its variables: `(class, name, type)`) and an LD body.
pub(crate) fn project(vars: &[(&str, &str, &str)], ld: &str) -> String {
    project_in("LD", vars, ld)
}

/// [`project`] with a body in `lang` (`LD`, `FBD`).
pub(crate) fn project_in(lang: &str, vars: &[(&str, &str, &str)], body: &str) -> String {
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

pub(crate) fn conn(from: &[u32]) -> String {
    let c: Vec<String> = from
        .iter()
        .map(|r| format!("<connection refLocalId=\"{r}\"/>"))
        .collect();
    format!("<connectionPointIn>{}</connectionPointIn>", c.concat())
}

pub(crate) fn rail(id: u32) -> String {
    format!("<leftPowerRail localId=\"{id}\"><connectionPointOut formalParameter=\"\"/></leftPowerRail>")
}

pub(crate) fn contact(id: u32, var: &str, from: &[u32], attrs: &str) -> String {
    format!(
        "<contact localId=\"{id}\" {attrs}>{}<connectionPointOut/><variable>{var}</variable></contact>",
        conn(from)
    )
}

pub(crate) fn coil(id: u32, var: &str, from: &[u32], attrs: &str) -> String {
    format!(
        "<coil localId=\"{id}\" {attrs}>{}<connectionPointOut/><variable>{var}</variable></coil>",
        conn(from)
    )
}

pub(crate) fn in_var(id: u32, expr: &str) -> String {
    format!("<inVariable localId=\"{id}\"><connectionPointOut/><expression>{expr}</expression></inVariable>")
}

/// A source of a block's input: `(localId, Some(output pin))`.
pub(crate) type Source<'a> = (u32, Option<&'a str>);

/// A block's inputs: `(pin, sources)`.
pub(crate) type Wires<'a> = &'a [(&'a str, &'a [Source<'a>])];

/// An FBD block: `(pin, sources)` inputs (a source `(localId, Some(pin))`), output pin names.
pub(crate) fn block(
    id: u32,
    ty: &str,
    instance: Option<&str>,
    inputs: Wires,
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
pub(crate) fn var_in(tag: &str, id: u32, expr: &str, from: (u32, Option<&str>)) -> String {
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

/// The JSON report of an XML text (read from standard input); the command must succeed.
pub(crate) fn report(xml: &str) -> serde_json::Value {
    report_and_warnings(xml).0
}

/// [`report`], with the command's standard error (its warnings).
pub(crate) fn report_and_warnings(xml: &str) -> (serde_json::Value, String) {
    json_output(&["report", "-", "--format", "json"], xml)
}

/// The JSON standard output of `plc-deps ARGS` (with `stdin`), which must succeed, and its
/// standard error.
pub(crate) fn json_output(args: &[&str], stdin: &str) -> (serde_json::Value, String) {
    let out = crate::common::cli::run_stdin(args, stdin.as_bytes());
    let err = crate::common::cli::one_line(&String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(0), "{err}");
    (serde_json::from_slice(&out.stdout).unwrap(), err)
}

/// Each rung of a JSON report: its id, what it reads (IN) and what it writes (OUT).
pub(crate) fn io(r: &serde_json::Value) -> Vec<(String, serde_json::Value, serde_json::Value)> {
    r["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| {
            (
                x["id"].as_str().unwrap().to_owned(),
                x["in"].clone(),
                x["out"].clone(),
            )
        })
        .collect()
}

/// One rung of a JSON report as [`io`] gives it.
pub(crate) fn rung(
    id: &str,
    ins: &[&str],
    outs: &[&str],
) -> (String, serde_json::Value, serde_json::Value) {
    (
        id.to_owned(),
        serde_json::json!(ins),
        serde_json::json!(outs),
    )
}

/// The JSON output of `plc-deps run` of the XML text for `scans` scans (from standard input;
/// `--allow-skipped`: an ST body runs as its stand-in rungs).
pub(crate) fn run_scans(xml: &str, scans: u32) -> serde_json::Value {
    let n = scans.to_string();
    let args = [
        "run",
        "-",
        "--scans",
        &n,
        "--format",
        "json",
        "--allow-skipped",
    ];
    json_output(&args, xml).0
}

/// The JSON output of `plc-deps run` of the XML text (written to the scratch file `tag.xml`),
/// one scan per row of `inputs` (a CSV with a header of input names), with `extra` arguments.
pub(crate) fn run_inputs(tag: &str, xml: &str, inputs: &str, extra: &[&str]) -> serde_json::Value {
    let path = crate::common::cli::tmp(&format!("{tag}.xml"));
    std::fs::write(&path, xml).unwrap();
    let csv = crate::common::cli::tmp(&format!("{tag}.csv"));
    std::fs::write(&csv, inputs).unwrap();
    let mut args = vec![
        "run",
        path.to_str().unwrap(),
        "--inputs",
        csv.to_str().unwrap(),
        "--format",
        "json",
        "--allow-skipped",
    ];
    args.extend(extra);
    json_output(&args, "").0
}

/// Runs the XML text one scan per row of `inputs` ([`run_inputs`]) and returns, for each of
/// `columns`, its value after each scan as the trace writes it.
pub(crate) fn trace(tag: &str, xml: &str, inputs: &str, columns: &[&str]) -> Vec<Vec<String>> {
    let tr = crate::common::cli::tmp(&format!("{tag}-trace.csv"));
    run_inputs(tag, xml, inputs, &["--trace", tr.to_str().unwrap()]);
    trace_columns(&tr, columns)
}

/// For each of `columns`, its value after each scan in the trace file `tr`.
pub(crate) fn trace_columns(tr: &std::path::Path, columns: &[&str]) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(tr).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let rows: Vec<Vec<&str>> = lines.map(|l| l.split(',').collect()).collect();
    columns
        .iter()
        .map(|c| {
            let k = header
                .iter()
                .position(|h| h == c)
                .unwrap_or_else(|| panic!("no column {c} in {header:?}"));
            rows.iter().map(|r| r[k].to_owned()).collect()
        })
        .collect()
}

/// The line and column (`L:C`, 1-based) where `needle` first starts in `text`.
pub(crate) fn line_col(text: &str, needle: &str) -> String {
    let at = text.find(needle).unwrap();
    let line = text[..at].matches('\n').count() + 1;
    let col = at - text[..at].rfind('\n').map_or(0, |k| k + 1) + 1;
    format!("{line}:{col}")
}
