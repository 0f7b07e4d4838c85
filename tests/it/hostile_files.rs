//! Files that are not plain files, or that someone else prepared: `-o` to a device, a FIFO, a
//! symbolic link, a 255-byte name, symbolic links planted at the temporary names of older
//! versions (`.NAME.tmp-PID`), a write that fails midway (a file size limit), standard output
//! that is full (`/dev/full`) or closed (`| head -c1`), an endless device or FIFO as the program
//! or `--inputs`, and `c -o DIR` stopped by SIGTERM.
//!
//! Memory is bounded with `ulimit -v` on the child (through `sh -c`) and every child that could
//! hang runs under a watchdog ([`wait_within`]) that kills it and fails the test.

use crate::common;

use common::cli::{error_line, files_in, generated, root, run, temp_files_in, tmp};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

const BIN: &str = env!("CARGO_BIN_EXE_plc-deps");
const PROGRAM: &str = "analyses/example-a/program.json";

/// A fresh folder of its own for one test (the leftover checks look at everything in it).
fn folder(name: &str) -> PathBuf {
    let dir = tmp(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Waits for `child` at most `secs` seconds (a watchdog against hangs, not a timing
/// assertion): kills it and fails if it has not ended by then.
fn wait_within(mut child: Child, secs: u64, what: &str) -> Output {
    let start = Instant::now();
    loop {
        if child.try_wait().unwrap().is_some() {
            return child.wait_with_output().unwrap();
        }
        if start.elapsed() > Duration::from_secs(secs) {
            let _ = child.kill();
            let _ = child.wait();
            panic!("{what}: still running after {secs} s");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs `script` with `sh -c` (`$0` is the binary), in the checkout, under a watchdog.
fn sh(script: &str, what: &str) -> Output {
    let child = Command::new("sh")
        .args(["-c", script, BIN])
        .current_dir(root())
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    wait_within(child, 120, what)
}

/// The `report` of the test program, as written to standard output.
fn report_text() -> Vec<u8> {
    let out = run(&["report", PROGRAM]);
    assert!(out.status.success());
    out.stdout
}

fn is_root() -> bool {
    let out = Command::new("id").arg("-u").output().unwrap();
    String::from_utf8_lossy(&out.stdout).trim() == "0"
}

#[test]
fn o_dev_null_is_written_and_stays_a_character_device() {
    let check = |out: &Output, what: &str| {
        assert!(
            out.status.success(),
            "{what}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(out.stdout.is_empty() || what == "run --trace", "{what}");
        let meta = std::fs::symlink_metadata("/dev/null").unwrap();
        assert!(
            meta.file_type().is_char_device(),
            "{what}: /dev/null replaced"
        );
    };
    check(&run(&["report", PROGRAM, "-o", "/dev/null"]), "report");
    check(&run(&["schema", "-o", "/dev/null"]), "schema");
    check(
        &run(&["run", PROGRAM, "--scans", "3", "-o", "/dev/null"]),
        "run",
    );
    check(
        &run(&["run", PROGRAM, "--scans", "3", "--trace", "/dev/null"]),
        "run --trace",
    );
    // Both ways: as root (a rename over /dev/null would succeed) and as an unprivileged user
    // (creating a temporary file in /dev fails). In CI the tests may run as either.
    if is_root() {
        let out = Command::new("setpriv")
            .args(["--reuid=65534", "--regid=65534", "--clear-groups", BIN])
            .args(["report", PROGRAM, "-o", "/dev/null"])
            .current_dir(root())
            .output()
            .expect("setpriv (util-linux) runs the binary as nobody");
        check(&out, "report as nobody");
    }
}

#[test]
fn o_fifo_gets_the_output_from_a_reader_thread() {
    let dir = folder("hostile-fifo");
    let fifo = dir.join("pipe");
    let made = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(made.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(&fifo).unwrap())
    };
    let child = Command::new(BIN)
        .args(["report", PROGRAM, "-o", fifo.to_str().unwrap()])
        .current_dir(root())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let out = wait_within(child, 60, "report -o FIFO");
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    // Checked first: had the FIFO been replaced, the reader would wait for a writer forever.
    let meta = std::fs::symlink_metadata(&fifo).unwrap();
    assert!(meta.file_type().is_fifo(), "the FIFO was replaced");
    assert_eq!(reader.join().unwrap(), report_text());
    assert!(temp_files_in(&dir).is_empty());
}

#[test]
fn o_symbolic_link_is_refused_and_neither_it_nor_its_target_changes() {
    let dir = folder("hostile-symlink");
    let target = dir.join("target.txt");
    std::fs::write(&target, "keep").unwrap();
    let link = dir.join("link.txt");
    std::os::unix::fs::symlink(&target, &link).unwrap();
    let dangling = dir.join("dangling.txt");
    let nowhere = dir.join("nowhere.txt");
    std::os::unix::fs::symlink(&nowhere, &dangling).unwrap();
    let folder_link = dir.join("folder-link");
    let real_folder = dir.join("real-folder");
    std::fs::create_dir(&real_folder).unwrap();
    std::os::unix::fs::symlink(&real_folder, &folder_link).unwrap();
    let refused = |path: &Path, role: &str| {
        format!(
            "error: cannot write {role} {}: it is a symbolic link, which is not followed (name the file it points to)",
            path.display()
        )
    };
    let (l, d) = (link.to_str().unwrap(), dangling.to_str().unwrap());
    for args in [
        vec!["report", PROGRAM, "-o", l],
        vec!["schema", "-o", l],
        vec!["gen", "--rungs", "10", "-o", d],
        vec!["run", PROGRAM, "--scans", "2", "-o", d],
    ] {
        let line = error_line(&run(&args), args[0]);
        let path = if args.contains(&l) { &link } else { &dangling };
        assert_eq!(line, refused(path, "-o"), "{args:?}");
    }
    assert_eq!(
        error_line(
            &run(&["run", PROGRAM, "--scans", "2", "--trace", l]),
            "trace"
        ),
        refused(&link, "--trace")
    );
    let f = folder_link.to_str().unwrap();
    assert_eq!(
        error_line(&run(&["c", PROGRAM, "-o", f, "--force"]), "c"),
        refused(&folder_link, "-o")
    );
    assert_eq!(std::fs::read_link(&link).unwrap(), target);
    assert_eq!(std::fs::read_to_string(&target).unwrap(), "keep");
    assert_eq!(std::fs::read_link(&dangling).unwrap(), nowhere);
    assert!(!nowhere.exists());
    assert_eq!(std::fs::read_link(&folder_link).unwrap(), real_folder);
    assert_eq!(std::fs::read_dir(&real_folder).unwrap().count(), 0);
    assert!(temp_files_in(&dir).is_empty());
}

/// Starts `plc-deps ARGS` reading the program from standard input, plants a symbolic link at
/// each of `names(pid)` (the temporary names older versions used) pointing at `victim`, then
/// feeds the program and returns the run.
fn with_planted_links(args: &[&str], names: impl Fn(u32) -> Vec<PathBuf>, victim: &Path) -> Output {
    use std::io::Write;
    let mut child = Command::new(BIN)
        .args(args)
        .current_dir(root())
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    for name in names(child.id()) {
        std::os::unix::fs::symlink(victim, name).unwrap();
    }
    let program = std::fs::read(root().join(PROGRAM)).unwrap();
    let mut stdin = child.stdin.take().unwrap();
    stdin.write_all(&program).unwrap();
    drop(stdin);
    wait_within(child, 60, "planted links")
}

#[test]
fn links_planted_at_the_old_predictable_temporary_names_are_not_followed() {
    let dir = folder("hostile-planted");
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "victim").unwrap();
    let out_file = dir.join("r.txt");
    let o = out_file.to_str().unwrap();
    let out = with_planted_links(
        &["report", "-", "-o", o],
        |pid| vec![dir.join(format!(".r.txt.tmp-{pid}"))],
        &victim,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "victim");
    let meta = std::fs::symlink_metadata(&out_file).unwrap();
    assert!(meta.is_file(), "r.txt is the report, not a planted link");
    let report = String::from_utf8(report_text()).unwrap();
    let written = std::fs::read_to_string(&out_file).unwrap();
    // The same report but for the file's name (`<stdin>`).
    assert_eq!(written.lines().count(), report.lines().count(), "{written}");

    // `c -o DIR --force`: links at `.DIR.tmp-PID` and `.DIR.old-PID` to a folder of the victim.
    let victim_dir = dir.join("victim-folder");
    std::fs::create_dir(&victim_dir).unwrap();
    std::fs::write(victim_dir.join("keep.txt"), "keep").unwrap();
    let c_dir = dir.join("c-out");
    std::fs::create_dir(&c_dir).unwrap();
    std::fs::write(c_dir.join("old.txt"), "old").unwrap();
    let out = with_planted_links(
        &["c", "-", "-o", c_dir.to_str().unwrap(), "--force"],
        |pid| {
            vec![
                dir.join(format!(".c-out.tmp-{pid}")),
                dir.join(format!(".c-out.old-{pid}")),
            ]
        },
        &victim_dir,
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(c_dir.join("main.c").is_file() && !c_dir.join("old.txt").exists());
    let victims = files_in(&victim_dir, |_| true);
    assert_eq!(victims, ["keep.txt"]);
    assert_eq!(
        std::fs::read_to_string(victim_dir.join("keep.txt")).unwrap(),
        "keep"
    );
    // Only the planted links are left beside the outputs.
    let mut left = files_in(&dir, |n| n.starts_with('.'));
    left.sort();
    assert_eq!(left.len(), 3, "{left:?}");
    for n in &left {
        assert!(
            std::fs::symlink_metadata(dir.join(n))
                .unwrap()
                .file_type()
                .is_symlink(),
            "{n}"
        );
    }
}

#[test]
fn a_255_byte_name_works_for_o_and_for_c() {
    let dir = folder("hostile-long");
    let name = format!("{}.txt", "n".repeat(251));
    assert_eq!(name.len(), 255);
    let file = dir.join(&name);
    let out = run(&["report", PROGRAM, "-o", file.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(std::fs::read(&file).unwrap(), report_text());
    let c_dir = dir.join("d".repeat(255));
    let out = run(&["c", PROGRAM, "-o", c_dir.to_str().unwrap()]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(c_dir.join("main.c").is_file());
    assert!(temp_files_in(&dir).is_empty());
}

#[test]
fn a_write_that_fails_midway_leaves_the_old_file_and_no_temporary_one() {
    let dir = folder("hostile-fsize");
    let out_file = dir.join("g.json");
    std::fs::write(&out_file, "old").unwrap();
    // A file size limit of 8 blocks of 512 bytes: the write fails with EFBIG (SIGXFSZ ignored).
    let o = out_file.to_str().unwrap();
    let out = sh(
        &format!("trap '' XFSZ; ulimit -f 8; exec \"$0\" gen --rungs 20000 -o '{o}'"),
        "gen -o over the limit",
    );
    assert_eq!(
        error_line(&out, "gen -o"),
        format!("error: cannot write -o {o}: File too large")
    );
    assert_eq!(std::fs::read_to_string(&out_file).unwrap(), "old");
    assert!(temp_files_in(&dir).is_empty(), "{:?}", temp_files_in(&dir));
    // Standard output redirected to a file: the same error, named <stdout>.
    let redirected = dir.join("stdout.json");
    let r = redirected.to_str().unwrap();
    let out = sh(
        &format!("trap '' XFSZ; ulimit -f 8; exec \"$0\" gen --rungs 20000 > '{r}'"),
        "gen > over the limit",
    );
    assert_eq!(
        error_line(&out, "gen >"),
        "error: cannot write <stdout>: File too large"
    );
}

#[test]
fn a_full_standard_output_is_exit_2_with_a_message() {
    for args in [
        vec!["--help"],
        vec!["--version"],
        vec!["schema"],
        vec!["report", PROGRAM],
        vec!["gen", "--rungs", "100"],
        vec!["run", PROGRAM, "--scans", "2"],
    ] {
        let full = std::fs::OpenOptions::new()
            .write(true)
            .open("/dev/full")
            .unwrap();
        let out = Command::new(BIN)
            .args(&args)
            .current_dir(root())
            .stdout(Stdio::from(full))
            .stderr(Stdio::piped())
            .output()
            .unwrap();
        assert_eq!(
            error_line(&out, args[0]),
            "error: cannot write <stdout>: No space left on device",
            "{args:?}"
        );
    }
}

#[test]
fn a_closed_standard_output_pipe_ends_quietly() {
    use std::io::Read;
    for args in [
        vec!["gen", "--rungs", "100000"],
        vec!["report", PROGRAM, "--format", "json"],
    ] {
        let mut child = Command::new(BIN)
            .args(&args)
            .current_dir(root())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // `| head -c1`: one byte read, then the pipe is closed.
        let mut one = [0u8; 1];
        child.stdout.take().unwrap().read_exact(&mut one).unwrap();
        let out = wait_within(child, 60, "closed pipe");
        assert_eq!(
            out.status.code(),
            Some(0),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(
            out.stderr.is_empty(),
            "{args:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
}

/// Virtual memory the reading children may use (`ulimit -v`, KiB): far less than reading up to
/// the 2 GiB limit would take, far more than the commands need otherwise.
const MEMORY_KIB: u64 = 1 << 20;

#[test]
fn an_endless_device_as_the_program_or_inputs_is_refused_early() {
    let out = sh(
        &format!("ulimit -v {MEMORY_KIB}; exec \"$0\" report /dev/zero"),
        "report /dev/zero",
    );
    assert_eq!(
        error_line(&out, "report /dev/zero"),
        "error: cannot read the program /dev/zero: binary data, not text (a NUL byte at offset 0)"
    );
    let out = sh(
        &format!("ulimit -v {MEMORY_KIB}; exec \"$0\" run {PROGRAM} --inputs /dev/zero"),
        "run --inputs /dev/zero",
    );
    assert_eq!(
        error_line(&out, "run --inputs /dev/zero"),
        "error: cannot read --inputs /dev/zero: binary data, not text (a NUL byte at offset 0)"
    );
}

/// Text without end (`yes`) through a pipe: only the cap stops it. The cap is lowered to 1 MiB
/// for the test (`PLC_DEPS_MAX_INPUT_BYTES`); without a cap the child would read until
/// `ulimit -v` ends it with an allocation failure, not exit code 2.
#[test]
fn an_endless_fifo_as_the_program_or_inputs_stops_at_the_cap() {
    let cap = "PLC_DEPS_MAX_INPUT_BYTES=1048576";
    let out = sh(
        &format!("ulimit -v {MEMORY_KIB}; yes | {cap} exec \"$0\" report /dev/stdin"),
        "report endless",
    );
    assert_eq!(
        error_line(&out, "report endless"),
        "error: cannot read the program /dev/stdin: the file is larger than the limit of 1048576 bytes"
    );
    let out = sh(
        &format!("ulimit -v {MEMORY_KIB}; yes | {cap} exec \"$0\" report -"),
        "report - endless",
    );
    assert_eq!(
        error_line(&out, "report - endless"),
        "error: cannot read the program <stdin>: the file is larger than the limit of 1048576 bytes"
    );
    let out = sh(
        &format!(
            "ulimit -v {MEMORY_KIB}; yes | {cap} exec \"$0\" run {PROGRAM} --inputs /dev/stdin"
        ),
        "run --inputs endless",
    );
    assert_eq!(
        error_line(&out, "run --inputs endless"),
        "error: cannot read --inputs /dev/stdin: the file is larger than the limit of 1048576 bytes"
    );
    // A regular file over the lowered cap is refused on its size.
    let dir = folder("hostile-cap");
    let big = dir.join("big.json");
    std::fs::write(&big, vec![b' '; (1 << 20) + 1]).unwrap();
    let b = big.to_str().unwrap();
    let out = sh(&format!("{cap} exec \"$0\" report '{b}'"), "big file");
    assert_eq!(
        error_line(&out, "big file"),
        format!("error: cannot read the program {b}: the file is larger than the limit of 1048576 bytes (1048577 bytes)")
    );
}

/// Starts `c PROGRAM -o DIR/out` and sends SIGTERM as soon as its temporary folder appears;
/// `None` if the command ended before that (it was too quick for this poll), else its run.
fn c_stopped_while_writing(program: &Path, dir: &Path) -> Option<Output> {
    let out_dir = dir.join("out");
    let mut child = Command::new(BIN)
        .args([
            "c",
            program.to_str().unwrap(),
            "-o",
            out_dir.to_str().unwrap(),
        ])
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while files_in(dir, |n| n.starts_with(".out.tmp-")).is_empty() {
        if child.try_wait().unwrap().is_some() {
            return None;
        }
        assert!(start.elapsed().as_secs() < 120, "c did not start writing");
        std::thread::sleep(Duration::from_millis(1));
    }
    let pid = i32::try_from(child.id()).unwrap();
    // SAFETY: kill(2) with a valid signal number on our own child's id, which cannot have been
    // reused: the child has not been waited for.
    let sent = unsafe { libc::kill(pid, libc::SIGTERM) };
    assert_eq!(sent, 0);
    Some(wait_within(child, 60, "c after SIGTERM"))
}

#[test]
fn c_stopped_by_sigterm_leaves_no_temporary_folder() {
    // 200,000 rungs: 35 MB of C, written in a few tenths of a second.
    let program = generated("hostile-c-big.json", &["--rungs", "200000"]);
    let dir = folder("hostile-c-signal");
    let out = (0..5)
        .find_map(|_| {
            let _ = std::fs::remove_dir_all(dir.join("out"));
            c_stopped_while_writing(&program, &dir)
        })
        .expect("the temporary folder was seen in one of five runs");
    assert_eq!(
        out.status.code(),
        Some(130),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        files_in(&dir, |_| true).is_empty(),
        "{:?}",
        files_in(&dir, |_| true)
    );
}
