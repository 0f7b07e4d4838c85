//! PLCopen projects as wholes: tasks and program instances, a CODESYS ST body,
//! recognition by content. What each of the editors' real files (tests/plcopen/, copied from
//! /work/shared/plcopen with their MANIFEST.md) gives is pinned, whole, by the committed outputs
//! of analyses/plcopen/ (tests/it/analyses.rs).

use crate::common;
use crate::plcopen_common as px;

use common::cli::run;
use px::{coil, contact, json_output, rail, NS};
use serde_json::Value;

fn pou(name: &str, var: (&str, &str), ld: &str) -> String {
    format!(
        "<pou name=\"{name}\" pouType=\"program\"><interface><localVars><variable name=\"{}\"><type><BOOL/></type></variable><variable name=\"{}\"><type><BOOL/></type></variable></localVars></interface><body><LD>{ld}</LD></body></pou>",
        var.0, var.1
    )
}

fn rung_ids(r: &Value) -> Vec<String> {
    r["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["id"].as_str().unwrap().to_owned())
        .collect()
}

#[test]
fn tasks_run_their_program_instances_in_priority_order() {
    let a = pou(
        "A",
        ("a", "x"),
        &[rail(1), contact(2, "a", &[1], ""), coil(3, "x", &[2], "")].concat(),
    );
    let b = pou(
        "B",
        ("b", "y"),
        &[rail(1), contact(2, "b", &[1], ""), coil(3, "y", &[2], "")].concat(),
    );
    let xml = format!(
        "<project xmlns=\"{NS}\"><types><pous>{a}{b}</pous></types><instances><configurations><configuration name=\"C\"><resource name=\"R\">\
         <task name=\"Slow\" priority=\"5\" interval=\"T#100ms\"><pouInstance name=\"ia\" typeName=\"A\"/></task>\
         <task name=\"Fast\" priority=\"1\" interval=\"T#10ms\"><pouInstance name=\"ib\" typeName=\"B\"/></task>\
         </resource></configuration></configurations></instances></project>"
    );
    let (r, err) = json_output(&["report", "-", "--format", "json"], &xml);
    assert_eq!(rung_ids(&r), ["Fast.B", "Slow.A", "A.R1", "B.R1"]);
    let col = xml.find("<resource").unwrap() + 1;
    assert_eq!(
        err.lines().filter(|l| l.starts_with("warning: ")).collect::<Vec<_>>(),
        [format!("warning: <stdin>:1:{col}: tasks Fast (T#10ms, priority 1), Slow (T#100ms, priority 5) run one after another in every scan (in priority order), not each at its own interval")]
    );
}

#[test]
fn a_codesys_st_body_is_analysed_per_statement_with_a_warning() {
    let (r, err) = json_output(
        &[
            "report",
            "tests/plcopen/e-cockpit-python-scripting__plc.xml",
            "--format",
            "json",
        ],
        "",
    );
    let rung = &r["rungs"][0];
    assert_eq!(rung["id"], "PLC_PRG.st1");
    assert_eq!(rung["in"], serde_json::json!(["i"]));
    assert_eq!(rung["out"], serde_json::json!(["i"]));
    assert!(err.contains("warning: tests/plcopen/e-cockpit-python-scripting__plc.xml:36:11: pou PLC_PRG: its ST body is analysed per statement (1 top-level statement, rungs PLC_PRG.st1 …, each reading and writing whole variables) and executed by `run` and `c` as the rungs it is lowered to (docs/plcopen.md, ST bodies)"), "{err}");
    assert!(err.contains("warning: tests/plcopen/e-cockpit-python-scripting__plc.xml:16:5: vendor data (addData) ignored: http://www.3s-software.com/plcopenxml/projectinformation"), "{err}");
}

#[test]
fn a_program_is_recognised_by_its_content_not_its_extension() {
    let xml =
        std::fs::read_to_string(common::cli::root().join("tests/plcopen/llf-actuators__plc.xml"))
            .unwrap();
    let path = common::cli::tmp("actuators.json");
    std::fs::write(&path, xml).unwrap();
    for cmd in ["report", "order"] {
        let out = run(&[cmd, path.to_str().unwrap()]);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{cmd}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let out = run(&[
        "run",
        path.to_str().unwrap(),
        "--scans",
        "3",
        "--format",
        "json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A function POU of the project: not a part of the model; an ST call of it (and of an unknown
/// function) is a black box reading its arguments and writing what the call assigns.
#[test]
fn a_function_of_the_project_called_from_st_is_seen_through_its_body() {
    let func = "<pou name=\"Avg\" pouType=\"function\"><interface><returnType><REAL/></returnType><inputVars><variable name=\"a\"><type><REAL/></type></variable><variable name=\"b\"><type><REAL/></type></variable></inputVars></interface><body><ST><xhtml xmlns=\"http://www.w3.org/1999/xhtml\">Avg := (a + b) / 2.0;</xhtml></ST></body></pou>";
    let xml = px::project_in(
        "ST",
        &[
            ("inputVars", "x", "REAL"),
            ("inputVars", "y", "REAL"),
            ("outputVars", "m", "REAL"),
            ("outputVars", "n", "REAL"),
        ],
        "<xhtml xmlns=\"http://www.w3.org/1999/xhtml\">m := Avg(x, y);\nn := Other(IN := m);</xhtml>",
    )
    .replace("<pous>", &format!("<pous>{func}"));
    let (r, err) = px::report_and_warnings(&xml);
    // Avg is executed (user_functions.rs): P.st1 reads the arguments x, y and writes m, and
    // calls Avg's body through the instance st__Avg; Other, unknown, stays a black box.
    let io = px::io(&r);
    let st1 = io.iter().find(|x| x.0 == "P.st1").expect("P.st1");
    for v in ["x", "y"] {
        assert!(
            st1.1.as_array().unwrap().contains(&serde_json::json!(v)),
            "{st1:?}"
        );
    }
    assert!(
        st1.2.as_array().unwrap().contains(&serde_json::json!("m")),
        "{st1:?}"
    );
    assert!(
        io.contains(&px::rung("P.st2", &["m", "n"], &["n"])),
        "{io:?}"
    );
    assert!(io.iter().any(|x| x.0 == "st__Avg:Avg.st1"), "{io:?}");
    let f = px::line_col(&xml, "<pou name=\"Avg\"");
    assert!(err.contains(&format!("<stdin>:{f}: pou Avg: a function; its calls in ST bodies are executed as calls of its body")), "{err}");
    assert!(err.contains("; the project's functions it calls are seen and executed through their bodies: Avg; the functions it calls are black boxes (the arguments read, the result and outputs written where the call assigns them): Other"), "{err}");
    let no_return = xml.replace("<returnType><REAL/></returnType>", "");
    let out = common::cli::run_stdin(&["report", "-"], no_return.as_bytes());
    let e = common::cli::error_line(&out, "function without a return type");
    assert_eq!(
        e,
        format!("error: <stdin>:{f}: at pou Avg: function `Avg` has no return type")
    );
}

/// A program POU whose LD body is one rung `contact read → coil write`, both globals it names
/// external.
fn global_pou(name: &str, read: &str, write: &str) -> String {
    let ext: String = [read, write]
        .iter()
        .map(|v| format!("<variable name=\"{v}\"><type><BOOL/></type></variable>"))
        .collect();
    let ld = [
        rail(1),
        contact(2, read, &[1], ""),
        coil(3, write, &[2], ""),
    ]
    .concat();
    format!("<pou name=\"{name}\" pouType=\"program\"><interface><externalVars>{ext}</externalVars></interface><body><LD>{ld}</LD></body></pou>")
}

/// Two tasks: Fast runs `fa` (program A: G3 → G1), Slow runs `sb` (B: G1 → G2) and `sc`
/// (C: G2 → G4); the resource itself runs `rd` (D: G3 → G5). Fast and the resource have the
/// lowest numbers, Slow priority 2.
pub(crate) fn two_task_project() -> String {
    let pous = [
        global_pou("A", "G3", "G1"),
        global_pou("B", "G1", "G2"),
        global_pou("C", "G2", "G4"),
        global_pou("D", "G3", "G5"),
    ]
    .concat();
    let globals: String = ["G1", "G2", "G3", "G4", "G5"]
        .iter()
        .map(|v| format!("<variable name=\"{v}\"><type><BOOL/></type></variable>"))
        .collect();
    format!(
        "<project xmlns=\"{NS}\"><types><pous>{pous}</pous></types><instances><configurations><configuration name=\"Cfg\"><globalVars>{globals}</globalVars><resource name=\"Res\">\
         <task name=\"Slow\" priority=\"2\" interval=\"T#100ms\"><pouInstance name=\"sb\" typeName=\"B\"/><pouInstance name=\"sc\" typeName=\"C\"/></task>\
         <task name=\"Fast\" priority=\"0\" single=\"G3\"><pouInstance name=\"fa\" typeName=\"A\"/></task>\
         <pouInstance name=\"rd\" typeName=\"D\"/>\
         </resource></configuration></configurations></instances></project>"
    )
}

#[test]
fn the_report_names_the_tasks_and_the_globals_programs_of_different_tasks_share() {
    let xml = two_task_project();
    let (r, _) = json_output(&["report", "-", "--format", "json"], &xml);
    let inst = |n: &str, p: &str| serde_json::json!({"name": n, "program": p});
    assert_eq!(
        r["configuration"],
        serde_json::json!({"name": "Cfg", "resources": [{"name": "Res", "tasks": [
            {"name": "Fast", "priority": 0, "interval": null, "single": "G3", "instances": [inst("fa", "A")]},
            {"name": "Slow", "priority": 2, "interval": "T#100ms", "single": null,
             "instances": [inst("sb", "B"), inst("sc", "C")]}],
          "instances": [inst("rd", "D")]}]})
    );
    let run = |t: Option<&str>, i: &str, p: &str| serde_json::json!({"task": t, "instance": i, "program": p});
    let (fa, sb, sc) = (
        run(Some("Fast"), "fa", "A"),
        run(Some("Slow"), "sb", "B"),
        run(Some("Slow"), "sc", "C"),
    );
    assert_eq!(
        r["programs"],
        serde_json::json!([fa, sb, sc, run(None, "rd", "D")])
    );
    // G1: A (Fast) writes, B (Slow) reads. G2 and G4 stay inside Slow; G3 and G5 are only read
    // across tasks (G5 written by the resource's D alone).
    assert_eq!(
        r["task_sharing"],
        serde_json::json!([{"var": "G1", "readers": [sb], "writers": [fa]}])
    );
    let out = run_stdout(&["report", "-"], &xml);
    let from = out
        .find("\nTasks of configuration")
        .expect("a tasks section");
    let to = out[from..].find("\nData dependences").unwrap() + from;
    assert_eq!(
        &out[from..to],
        "
Tasks of configuration Cfg, resource Res: 2 tasks
  task       priority  interval  single  program instances
  Fast       0         -         G3      fa (A)
  Slow       2         T#100ms   -       sb (B) sc (C)
  (no task)  -         -         -       rd (D)
Analysed: all 4 program instances, in task order: Fast.fa (A), Slow.sb (B), Slow.sc (C), rd (D)

Globals shared between tasks (one task may see another's half-finished scan): 1 variable
  variable  read by      written by
  G1        Slow.sb (B)  Fast.fa (A)
"
    );
}

/// The standard output of `plc-deps ARGS` with `stdin`, which must succeed.
fn run_stdout(args: &[&str], stdin: &str) -> String {
    let out = common::cli::run_stdin(args, stdin.as_bytes());
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn pou_selects_the_program_to_analyse_and_to_run() {
    let xml = two_task_project();
    // Any case, as IEC 61131-3 names are.
    let (r, _) = json_output(&["report", "-", "--format", "json", "--pou", "b"], &xml);
    assert_eq!(r["program"], "B");
    assert_eq!(rung_ids(&r), ["B.R1"]);
    assert_eq!(
        r["programs"],
        serde_json::json!([{"task": "Slow", "instance": "sb", "program": "B"}])
    );
    assert_eq!(r["task_sharing"], serde_json::json!([]));
    let out = run_stdout(&["report", "-", "--pou", "B"], &xml);
    assert!(
        out.contains("\nAnalysed: 1 program instance of 4: Slow.sb (B)\n"),
        "{out}"
    );
    // `run` runs B alone.
    let (r, _) = json_output(
        &["run", "-", "--scans", "1", "--format", "json", "--pou", "B"],
        &xml,
    );
    assert_eq!(r["program"], "B", "{r}");
}

#[test]
fn an_unknown_pou_is_one_error_listing_the_programs() {
    let xml = two_task_project();
    for cmd in ["report", "run"] {
        let out = common::cli::run_stdin(&[cmd, "-", "--pou", "Nope"], xml.as_bytes());
        assert_eq!(out.status.code(), Some(2));
        assert!(out.stdout.is_empty());
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            err.lines().take(2).collect::<Vec<_>>(),
            ["error[E0501]: --pou Nope: the project has no program of that name; its programs are A, B, C, D", "  --> <stdin>:1:1"],
            "{err}"
        );
    }
}

/// The report keys and text of the configuration, from the XML and from its conversion to the
/// JSON program format: the same.
#[test]
fn the_configuration_converted_to_json_reports_the_same_tasks_and_sharing() {
    let xml = two_task_project();
    let path = common::cli::tmp("two-task.xml");
    std::fs::write(&path, &xml).unwrap();
    let out = common::cli::run(&["convert", path.to_str().unwrap()]);
    assert_eq!(out.status.code(), Some(0));
    let json = String::from_utf8(out.stdout).unwrap();
    assert!(
        json.contains("\n\"configuration\": {\"name\": \"Cfg\", \"resources\": ["),
        "{json}"
    );
    let (from_xml, _) = json_output(&["report", "-", "--format", "json"], &xml);
    let (from_json, _) = json_output(&["report", "-", "--format", "json"], &json);
    for key in ["configuration", "programs", "task_sharing"] {
        assert!(
            from_xml[key].is_object() || from_xml[key].is_array(),
            "{key}"
        );
        assert_eq!(from_json[key], from_xml[key], "{key}");
    }
    let section = |out: &str| {
        let from = out
            .find("\nTasks of configuration")
            .expect("a tasks section");
        let to = out[from..].find("\nData dependences").unwrap() + from;
        out[from..to].to_owned()
    };
    assert_eq!(
        section(&run_stdout(&["report", "-"], &json)),
        section(&run_stdout(&["report", "-"], &xml))
    );
}

/// `--pou` on the JSON conversion of a project selects the same program as on the XML: the
/// same report, byte for byte, and the same scans; a name no instance runs is one located error.
#[test]
fn pou_selects_the_same_program_of_the_converted_json() {
    let xml = two_task_project();
    let path = common::cli::tmp("two-task-select.xml");
    std::fs::write(&path, &xml).unwrap();
    let json = run_stdout(&["convert", path.to_str().unwrap()], "");
    for pou in ["A", "b", "C", "D"] {
        for args in [
            &["report", "-", "--format", "json", "--pou", pou][..],
            &["report", "-", "--pou", pou],
            &["run", "-", "--scans", "3", "--format", "json", "--pou", pou],
        ] {
            let from_json = run_stdout(args, &json);
            let from_xml = run_stdout(args, &xml);
            // `run` measures its speed, which differs run to run.
            let strip = |s: &str| {
                let mut v: serde_json::Value = match serde_json::from_str(s) {
                    Ok(v) => v,
                    Err(_) => return s.to_owned(),
                };
                for timed in ["modes", "speedup", "speedup_block_scans", "plan_run"] {
                    v.as_object_mut().unwrap().remove(timed);
                }
                v.to_string()
            };
            assert_eq!(strip(&from_json), strip(&from_xml), "{args:?}");
        }
    }
    let out = common::cli::run_stdin(&["report", "-", "--pou", "Nope"], json.as_bytes());
    assert_eq!(out.status.code(), Some(2));
    assert!(out.stdout.is_empty());
    let err = String::from_utf8_lossy(&out.stderr);
    let first = err.lines().next().unwrap_or("");
    assert_eq!(
        first,
        "error[E0309]: --pou Nope: no program instance runs a program of that name; they run A, B, C, D",
        "{err}"
    );
    assert!(err.contains("at configuration"), "{err}");
}

/// `run` says which program instances each scan ran: all of them in task order, or the one
/// `--pou` selects; the JSON has them under `programs`.
#[test]
fn run_names_the_program_instances_it_ran() {
    let xml = two_task_project();
    let out = run_stdout(&["run", "-", "--scans", "1"], &xml);
    assert_eq!(
        out.lines().nth(1),
        Some("ran all 4 program instances each scan, one after another in task order: Fast.fa (A), Slow.sb (B), Slow.sc (C), rd (D) (--pou NAME runs one program alone)"),
        "{out}"
    );
    let (r, _) = json_output(&["run", "-", "--scans", "1", "--format", "json"], &xml);
    let run = |t: Option<&str>, i: &str, p: &str| serde_json::json!({"task": t, "instance": i, "program": p});
    assert_eq!(
        r["programs"],
        serde_json::json!([
            run(Some("Fast"), "fa", "A"),
            run(Some("Slow"), "sb", "B"),
            run(Some("Slow"), "sc", "C"),
            run(None, "rd", "D")
        ])
    );
    let out = run_stdout(&["run", "-", "--scans", "1", "--pou", "c"], &xml);
    assert_eq!(
        out.lines().nth(1),
        Some("ran 1 program instance of 4, selected by --pou: Slow.sc (C)"),
        "{out}"
    );
    let (r, _) = json_output(
        &["run", "-", "--scans", "1", "--format", "json", "--pou", "D"],
        &xml,
    );
    assert_eq!(r["programs"], serde_json::json!([run(None, "rd", "D")]));
    // A program without a configuration says nothing of instances, and has no `programs`.
    let json = r#"{"program": "p", "vars": [{"name": "x", "type": "BOOL", "class": "output"}], "rungs": [{"id": "R1", "ld": [{"coil": "x"}]}]}"#;
    let out = run_stdout(&["run", "-", "--scans", "1"], json);
    assert!(
        out.lines()
            .nth(1)
            .is_some_and(|l| l.starts_with("outputs after")),
        "{out}"
    );
    let (r, _) = json_output(&["run", "-", "--scans", "1", "--format", "json"], json);
    assert!(r.get("programs").is_none());
}

/// `run --pou` runs the selected program: the wxHMI example's `main` and `ReadGUIdata` (whose
/// string literal was refused before STRING had values) each run, and so does the whole project.
#[test]
fn run_pou_runs_the_selected_programs_body() {
    let file = "tests/plcopen/beremiz__tests_projects_wxHMI_plc.xml";
    for pou in [Some("main"), Some("ReadGUIdata"), None] {
        let mut args = vec!["run", file, "--scans", "2"];
        if let Some(p) = pou {
            args.extend(["--pou", p]);
        }
        let out = common::cli::run(&args);
        assert_eq!(
            out.status.code(),
            Some(0),
            "{pou:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}
