//! The HTML report in a real browser: headless Chromium (`/usr/bin/chromium`, which `.ci/run`
//! installs) opens the page of every `analyses/` example, the report's and the run's (the same
//! page with the run's measured figures: both modes' rates, the model's table, the outputs, checked
//! here as the browser shows them), and is driven over the DevTools
//! protocol on a pipe (`--remote-debugging-pipe`: NUL-terminated JSON on file descriptors 3 and
//! 4), with serde_json and the standard library only. Each page must load with no console error
//! and no uncaught exception, have a card for every rung, and highlight a rung's dependences
//! when the rung is clicked (a real mouse press and release at the card's centre). A
//! screenshot of each is written to `target/html-screenshots/`; with `UPDATE_EXPECT=1` those
//! of Examples A and B are also written to `docs/` (the README shows them), and the run page of
//! Example B at its run section (docs/html.md shows it).

use serde_json::{json, Value};
use std::io::{Read, Write};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{channel, Receiver};
use std::time::{Duration, Instant};

unsafe extern "C" {
    fn dup2(old: i32, new: i32) -> i32;
}

struct Browser {
    child: Child,
    to: std::io::PipeWriter,
    from: Receiver<Value>,
    next: u64,
    session: Option<String>,
    events: Vec<Value>,
    _profile: PathBuf,
}

impl Browser {
    fn start() -> Browser {
        let exe = "/usr/bin/chromium";
        assert!(
            Path::new(exe).exists(),
            "{exe} is missing: `apt-get install chromium` (.ci/run installs it)"
        );
        let profile =
            std::env::temp_dir().join(format!("plc-deps-chromium-{}", std::process::id()));
        let (child_in, to) = std::io::pipe().unwrap();
        let (mut from_r, child_out) = std::io::pipe().unwrap();
        use std::os::fd::AsRawFd;
        let (a, b) = (child_in.as_raw_fd(), child_out.as_raw_fd());
        let mut cmd = Command::new(exe);
        cmd.args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--hide-scrollbars",
            "--remote-debugging-pipe",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .arg("about:blank")
        .stdin(Stdio::null())
        .stdout(Stdio::null())
        .stderr(Stdio::null());
        // SAFETY: dup2 is async-signal-safe; the two descriptors are open in the child.
        unsafe {
            cmd.pre_exec(move || {
                // Through free high numbers first: a pipe may already be 3 or 4, and dup2 onto
                // itself would keep its close-on-exec flag.
                if dup2(a, 200) < 0 || dup2(b, 201) < 0 || dup2(200, 3) < 0 || dup2(201, 4) < 0 {
                    return Err(std::io::Error::last_os_error());
                }
                Ok(())
            });
        }
        let child = cmd.spawn().expect("start chromium");
        drop(child_in);
        drop(child_out);
        let (tx, rx) = channel();
        std::thread::spawn(move || {
            let mut buf = Vec::new();
            let mut chunk = [0u8; 65536];
            while let Ok(n) = from_r.read(&mut chunk) {
                if n == 0 {
                    break;
                }
                buf.extend_from_slice(&chunk[..n]);
                while let Some(i) = buf.iter().position(|&c| c == 0) {
                    let msg: Vec<u8> = buf.drain(..=i).collect();
                    if let Ok(v) = serde_json::from_slice(&msg[..msg.len() - 1]) {
                        if tx.send(v).is_err() {
                            return;
                        }
                    }
                }
            }
        });
        Browser {
            child,
            to,
            from: rx,
            next: 0,
            session: None,
            events: Vec::new(),
            _profile: profile,
        }
    }

    /// Sends a command and waits for its result (events that arrive meanwhile are kept).
    fn call(&mut self, method: &str, params: Value) -> Value {
        self.next += 1;
        let id = self.next;
        let mut msg = json!({"id": id, "method": method, "params": params});
        if let Some(s) = &self.session {
            msg["sessionId"] = json!(s);
        }
        let mut bytes = serde_json::to_vec(&msg).unwrap();
        bytes.push(0);
        self.to.write_all(&bytes).expect("write to chromium");
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|_| panic!("no answer to {method}"));
            if v["id"] == json!(id) {
                assert!(v.get("error").is_none(), "{method}: {v}");
                return v["result"].clone();
            }
            self.events.push(v);
        }
    }

    /// Waits for an event named `method`.
    fn wait_event(&mut self, method: &str) {
        if let Some(i) = self.events.iter().position(|e| e["method"] == method) {
            self.events.remove(i);
            return;
        }
        let deadline = Instant::now() + Duration::from_secs(60);
        loop {
            let left = deadline.saturating_duration_since(Instant::now());
            let v = self
                .from
                .recv_timeout(left)
                .unwrap_or_else(|_| panic!("no {method}"));
            if v["method"] == method {
                return;
            }
            self.events.push(v);
        }
    }

    fn eval(&mut self, expr: &str) -> Value {
        let r = self.call(
            "Runtime.evaluate",
            json!({"expression": expr, "returnByValue": true}),
        );
        assert!(r.get("exceptionDetails").is_none(), "{expr}: {r}");
        r["result"]["value"].clone()
    }

    /// Console errors, uncaught exceptions and error log entries seen so far.
    fn errors(&self) -> Vec<String> {
        self.events
            .iter()
            .filter(|e| {
                e["method"] == "Runtime.exceptionThrown"
                    || (e["method"] == "Runtime.consoleAPICalled" && e["params"]["type"] == "error")
                    || (e["method"] == "Log.entryAdded" && e["params"]["entry"]["level"] == "error")
            })
            .map(|e| e["params"].to_string())
            .collect()
    }

    fn click(&mut self, x: f64, y: f64) {
        for kind in ["mouseMoved", "mousePressed", "mouseReleased"] {
            self.call(
                "Input.dispatchMouseEvent",
                json!({"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1}),
            );
        }
    }
}

impl Drop for Browser {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        let _ = std::fs::remove_dir_all(&self._profile);
    }
}

fn decode_base64(s: &str) -> Vec<u8> {
    let val = |c: u8| match c {
        b'A'..=b'Z' => c - b'A',
        b'a'..=b'z' => c - b'a' + 26,
        b'0'..=b'9' => c - b'0' + 52,
        b'+' => 62,
        _ => 63,
    };
    let bytes: Vec<u8> = s.bytes().filter(|&c| c != b'=').collect();
    let mut out = Vec::with_capacity(bytes.len() * 3 / 4);
    for chunk in bytes.chunks(4) {
        let n = chunk
            .iter()
            .enumerate()
            .fold(0u32, |acc, (i, &c)| acc | (val(c) as u32) << (18 - 6 * i));
        out.extend_from_slice(&n.to_be_bytes()[1..chunk.len()]);
    }
    out
}

/// The page of an example, written by the command (`report`, or `run` for 20 scans) into the
/// target folder.
fn page_of(example: &str, command: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("html-pages");
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!("{example}-{command}.html"));
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_plc-deps"));
    cmd.current_dir(root).args([
        command,
        &format!("analyses/{example}/program.json"),
        "--format",
        "html",
        "-o",
    ]);
    cmd.arg(&out);
    if command == "run" {
        cmd.args(["--scans", "20"]);
    }
    let status = cmd.status().unwrap();
    // A run that faults still writes its page (exit 1).
    assert!(
        status.success() || (command == "run" && status.code() == Some(1)),
        "{example}"
    );
    out
}

/// The first dependence of the example's JSON report: (from, to).
fn first_dependence(example: &str) -> Option<(String, String)> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text =
        std::fs::read_to_string(root.join(format!("analyses/{example}/report.json"))).unwrap();
    let j: Value = serde_json::from_str(&text).unwrap();
    let d = j["dependences"].as_array()?.first()?;
    Some((d["from"].as_str()?.into(), d["to"].as_str()?.into()))
}

fn rung_ids(example: &str) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text =
        std::fs::read_to_string(root.join(format!("analyses/{example}/report.json"))).unwrap();
    let j: Value = serde_json::from_str(&text).unwrap();
    j["rungs"]
        .as_array()
        .unwrap()
        .iter()
        .map(|r| r["id"].as_str().unwrap().to_string())
        .collect()
}

/// Loads the page of `example` made by `command`: no console error, every rung's card, a click
/// on a rung highlighting its dependences; returns its screenshot.
fn check_page(b: &mut Browser, example: &str, command: &str) -> Vec<u8> {
    let file = page_of(example, command);
    b.events.clear();
    b.call(
        "Page.navigate",
        json!({"url": format!("file://{}", file.display())}),
    );
    b.wait_event("Page.loadEventFired");
    let errors = b.errors();
    assert!(errors.is_empty(), "{example}: {errors:?}");
    let ids = b.eval("Array.from(document.querySelectorAll('.card')).map(c => c.id)");
    let want: Vec<Value> = rung_ids(example)
        .iter()
        .map(|r| json!(format!("rung-{r}")))
        .collect();
    let mut got: Vec<Value> = ids.as_array().unwrap().clone();
    let mut want_sorted = want.clone();
    got.sort_by_key(|v| v.to_string());
    want_sorted.sort_by_key(|v| v.to_string());
    assert_eq!(got, want_sorted, "{example}: every rung has its card");
    if let Some((from, to)) = first_dependence(example) {
        // Click the dependent rung: the rung it depends on turns `dep`, the edge `hl`.
        let rect = b.eval(&format!(
            "(() => {{ const c = document.getElementById({:?}); c.scrollIntoView({{block: 'center', inline: 'center'}}); const r = c.getBoundingClientRect(); return [r.left + r.width / 2, r.top + 8]; }})()",
            format!("rung-{to}")
        ));
        let (x, y) = (rect[0].as_f64().unwrap(), rect[1].as_f64().unwrap());
        b.click(x, y);
        let state = b.eval(&format!(
            "[document.getElementById({:?}).classList.contains('sel'), document.getElementById({:?}).classList.contains('dep'), document.querySelectorAll('.e.hl').length > 0, document.getElementById('info').textContent]",
            format!("rung-{to}"),
            format!("rung-{from}")
        ));
        assert_eq!(state[0], json!(true), "{example}: clicked {to} is selected");
        assert_eq!(
            state[1],
            json!(true),
            "{example}: {from}, which {to} depends on, is marked"
        );
        assert_eq!(
            state[2],
            json!(true),
            "{example}: its edges are highlighted"
        );
        let info = state[3].as_str().unwrap();
        assert!(
            info.starts_with(&format!("{to} depends on ")) && info.contains(&from),
            "{info}"
        );
        b.eval("window.scrollTo(0, 0)");
    }
    if command == "run" {
        check_run_section(b, example);
        b.eval("document.getElementById('run').scrollIntoView()");
    }
    let shot = b.call("Page.captureScreenshot", json!({"format": "png"}));
    let png = decode_base64(shot["data"].as_str().unwrap());
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n", "{example}: a PNG");
    png
}

/// The run section as the browser shows it: both modes' rates (positive, µs/scan and scans/s
/// agreeing), the model's table for P = 1, 2, 4, 8, and one output row per output variable of
/// the example's committed run report.
fn check_run_section(b: &mut Browser, example: &str) {
    let rates = b.eval(
        "Array.from(document.querySelectorAll('#run table.rates tr')).slice(1).map(r => Array.from(r.cells).map(c => c.textContent))",
    );
    let rates = rates.as_array().unwrap();
    assert_eq!(rates.len(), 2, "{example}: seq and par");
    for (r, mode) in rates.iter().zip(["seq", "par"]) {
        assert_eq!(r[0], json!(mode), "{example}");
        let us: f64 = r[1].as_str().unwrap().parse().unwrap();
        let per_s: f64 = r[2].as_str().unwrap().replace(',', "").parse().unwrap();
        assert!(
            us > 0.0 && (us * per_s / 1e6 - 1.0).abs() < 0.05,
            "{example}: {r}"
        );
    }
    let par = rates[1][4].as_str().unwrap();
    assert!(
        par.starts_with("sequential fallback (") || par.ends_with(" over 20 scans"),
        "{example}: {par}"
    );
    let ideal = b.eval("document.querySelectorAll('#run table.ideal tr').length");
    assert_eq!(ideal, json!(5), "{example}: P = 1, 2, 4, 8");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(root.join(format!("analyses/{example}/run.json"))).unwrap();
    let j: Value = serde_json::from_str(&text).unwrap();
    let outputs = j["outputs"].as_object().unwrap().len();
    let shown = b.eval("document.querySelectorAll('#run table.outputs tr').length");
    let want = if outputs == 0 {
        0
    } else {
        outputs.min(500) + 1
    };
    assert_eq!(shown, json!(want), "{example}: the outputs");
    let visible =
        b.eval("document.querySelector('#run svg.ratios').getBoundingClientRect().width > 0");
    assert_eq!(
        visible,
        json!(true),
        "{example}: the speed-up chart is drawn"
    );
}

/// The report page and the run page of `example` in the browser; screenshots to `shots`.
fn check_example(b: &mut Browser, example: &str, shots: &Path) {
    let png = check_page(b, example, "report");
    std::fs::write(shots.join(format!("{example}.png")), &png).unwrap();
    let update = std::env::var_os("UPDATE_EXPECT").is_some();
    let docs = Path::new(env!("CARGO_MANIFEST_DIR")).join("docs");
    if update && ["example-a", "example-b"].contains(&example) {
        std::fs::write(docs.join(format!("html-{example}.png")), &png).unwrap();
    }
    let png = check_page(b, example, "run");
    std::fs::write(shots.join(format!("{example}-run.png")), &png).unwrap();
    if update && example == "example-b" {
        std::fs::write(docs.join("html-run-example-b.png"), &png).unwrap();
    }
}

#[test]
fn every_example_page_loads_clicks_and_highlights_in_chromium() {
    let shots = Path::new(env!("CARGO_TARGET_TMPDIR")).join("html-screenshots");
    std::fs::create_dir_all(&shots).unwrap();
    let mut b = Browser::start();
    let targets = b.call("Target.createTarget", json!({"url": "about:blank"}));
    let target = targets["targetId"].as_str().unwrap().to_string();
    let attached = b.call(
        "Target.attachToTarget",
        json!({"targetId": target, "flatten": true}),
    );
    b.session = Some(attached["sessionId"].as_str().unwrap().to_string());
    for m in ["Page.enable", "Runtime.enable", "Log.enable"] {
        b.call(m, json!({}));
    }
    b.call(
        "Emulation.setDeviceMetricsOverride",
        json!({"width": 1400, "height": 1000, "deviceScaleFactor": 1, "mobile": false}),
    );
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("analyses");
    let mut examples: Vec<String> = std::fs::read_dir(root)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.join("program.json").is_file())
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    examples.sort();
    assert!(examples.len() >= 11);
    for e in &examples {
        check_example(&mut b, e, &shots);
    }
    check_fault_chip(&mut b);
    check_tasks_section(&mut b, &shots);
}

/// A run that faults: its page lists the fault with its rung as a chip, and clicking the chip
/// selects the rung's card.
fn check_fault_chip(b: &mut Browser) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("html-pages");
    std::fs::create_dir_all(&dir).unwrap();
    let program = dir.join("faulty.json");
    std::fs::write(
        &program,
        r#"{"program": "faulty", "vars": [{"name": "d", "type": "INT", "class": "input"}, {"name": "x", "type": "INT", "class": "output"}, {"name": "q", "type": "BOOL", "class": "output"}],
  "rungs": [{"id": "DIV", "ld": [{"op": "DIV", "in": [10, "d"], "out": "x"}]},
            {"id": "Q", "ld": [{"compare": "GT", "a": "x", "b": 1}, {"coil": "q"}]}]}"#,
    )
    .unwrap();
    let page = dir.join("faulty-run.html");
    let status = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .arg("run")
        .arg(&program)
        .args(["--scans", "4", "--format", "html", "-o"])
        .arg(&page)
        .status()
        .unwrap();
    assert_eq!(status.code(), Some(1), "a faulted run");
    b.events.clear();
    b.call(
        "Page.navigate",
        json!({"url": format!("file://{}", page.display())}),
    );
    b.wait_event("Page.loadEventFired");
    assert!(b.errors().is_empty(), "{:?}", b.errors());
    let rows = b.eval(
        "Array.from(document.querySelectorAll('#run table.faults tr')).slice(1).map(r => Array.from(r.cells).map(c => c.textContent))",
    );
    assert_eq!(rows, json!([["DIV", "div-by-zero", "4", "0", "3"]]));
    let rect = b.eval(
        "(() => { const c = document.querySelector('#run table.faults .chip'); c.scrollIntoView({block: 'center'}); const r = c.getBoundingClientRect(); return [r.left + r.width / 2, r.top + r.height / 2]; })()",
    );
    b.click(rect[0].as_f64().unwrap(), rect[1].as_f64().unwrap());
    let state = b.eval(
        "[document.getElementById('rung-DIV').classList.contains('sel'), document.getElementById('rung-Q').classList.contains('user'), document.getElementById('info').textContent]",
    );
    assert_eq!(
        state[0],
        json!(true),
        "the faulting rung's card is selected"
    );
    assert_eq!(state[1], json!(true), "Q, which reads x, depends on it");
    assert!(
        state[2]
            .as_str()
            .unwrap()
            .starts_with("DIV depends on nothing; depending on it: Q"),
        "{state}"
    );
}

/// A program with a configuration (two tasks, the example of docs/format.md): its page has the
/// tasks section between the summary and the levels, drawn, with a row per task and per shared
/// global as the browser shows them; a screenshot of the section to `shots`.
fn check_tasks_section(b: &mut Browser, shots: &Path) {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("html-pages");
    std::fs::create_dir_all(&dir).unwrap();
    let program = dir.join("cell.json");
    std::fs::write(
        &program,
        r#"{"program": "cell",
 "vars": [{"name": "part_ready", "type": "BOOL"}, {"name": "clamp", "type": "BOOL"}],
 "rungs": [{"id": "Fast.feed", "ld": [{"call": "feed"}]}, {"id": "Slow.hold", "ld": [{"call": "hold"}]}],
 "subroutines": {
   "feed": {"rungs": [{"id": "f1", "ld": [{"contact": "clamp", "negated": true}, {"coil": "part_ready"}]}]},
   "hold": {"rungs": [{"id": "h1", "ld": [{"contact": "part_ready"}, {"set": "clamp"}]}]}},
 "configuration": {"name": "Cell", "resources": [
   {"name": "Cpu",
    "tasks": [{"name": "Fast", "priority": 0, "interval": "T#10ms", "instances": [{"name": "f", "program": "feed"}]},
              {"name": "Slow", "priority": 1, "interval": "T#100ms", "instances": [{"name": "h", "program": "hold"}]}]}]}}"#,
    )
    .unwrap();
    let page = dir.join("cell-report.html");
    let status = Command::new(env!("CARGO_BIN_EXE_plc-deps"))
        .arg("report")
        .arg(&program)
        .args(["--format", "html", "-o"])
        .arg(&page)
        .status()
        .unwrap();
    assert!(status.success());
    b.events.clear();
    b.call(
        "Page.navigate",
        json!({"url": format!("file://{}", page.display())}),
    );
    b.wait_event("Page.loadEventFired");
    assert!(b.errors().is_empty(), "{:?}", b.errors());
    let mut table = |which: &str| {
        b.eval(&format!(
            "Array.from(document.querySelectorAll('#tasks table.{which} tr')).slice(1).map(r => Array.from(r.cells).map(c => c.innerText))"
        ))
    };
    assert_eq!(
        table("tasks"),
        json!([
            ["Fast", "0", "T#10ms", "-", "f (feed)"],
            ["Slow", "1", "T#100ms", "-", "h (hold)"]
        ])
    );
    // In variable order (declaration order).
    assert_eq!(
        table("shared"),
        json!([
            ["part_ready", "Slow.h (hold)", "Fast.f (feed)"],
            ["clamp", "Fast.f (feed)", "Slow.h (hold)"]
        ])
    );
    let placed = b.eval(
        "(() => { const t = document.getElementById('tasks'), r = t.getBoundingClientRect(); const after = (a, b) => !!(a.compareDocumentPosition(b) & Node.DOCUMENT_POSITION_FOLLOWING); return [r.width > 0 && r.height > 0, after(document.getElementById('summary'), t), after(t, document.getElementById('levels')), t.querySelector('p.analysed').innerText]; })()",
    );
    assert_eq!(
        placed,
        json!([
            true,
            true,
            true,
            "Analysed: all 2 program instances, in task order: Fast.f (feed), Slow.h (hold)."
        ])
    );
    b.eval("document.getElementById('tasks').scrollIntoView()");
    let shot = b.call("Page.captureScreenshot", json!({"format": "png"}));
    let png = decode_base64(shot["data"].as_str().unwrap());
    assert_eq!(&png[..8], b"\x89PNG\r\n\x1a\n");
    std::fs::write(shots.join("cell-tasks.png"), &png).unwrap();
}
