//! How the tool writes its outputs (issue 18): FIFOs and device nodes written in place,
//! never replaced; the standard output (`-`); a closed pipe; interrupts; temporaries that
//! cannot be turned against the user and are cleaned up. Device nodes and FIFOs are made in
//! scratch directories, never in the machine's `/dev`.
#![cfg(unix)]

mod common;

use common::{dataset, scratch, text, toposmooth};
use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_toposmooth")
}

/// The names in `dir` that are the tool's temporaries.
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with(".toposmooth-"))
        .collect()
}

fn c_path(p: &Path) -> std::ffi::CString {
    std::ffi::CString::new(p.as_os_str().as_encoded_bytes()).unwrap()
}

fn mkfifo(p: &Path) {
    // SAFETY: a valid NUL-terminated path
    assert_eq!(unsafe { libc::mkfifo(c_path(p).as_ptr(), 0o600) }, 0, "mkfifo {}", p.display());
}

/// A character device like `/dev/null` (1, 3) made at `p`; `false` where this process may not
/// make device nodes (no CAP_MKNOD).
fn mknod_null(p: &Path) -> bool {
    // SAFETY: a valid NUL-terminated path
    unsafe { libc::mknod(c_path(p).as_ptr(), libc::S_IFCHR | 0o666, libc::makedev(1, 3)) == 0 }
}

fn fx() -> String {
    dataset("fx_eur_per_usd_daily_1999_2017.csv")
}

#[test]
fn a_fifo_output_is_written_through_and_stays_a_fifo() {
    let dir = scratch("fifo-out");
    let fifo = dir.join("smoothed.csv");
    mkfifo(&fifo);
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read_to_string(fifo).unwrap())
    };
    let o = toposmooth(&["smooth", &fx(), "-o", fifo.to_str().unwrap(), "--persistence", "2%"]);
    assert!(o.status.success(), "{}", text(&o));
    let csv = reader.join().unwrap();
    assert!(csv.starts_with("date,input,output,u,role\n1999-01-04,0.8466,0.8466,"), "{}", &csv[..60.min(csv.len())]);
    assert_eq!(csv.lines().count(), 4755, "header and 4754 samples");
    assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo(), "the FIFO is not replaced");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "nothing beside the FIFO");
}

#[test]
fn a_device_node_given_for_every_output_stays_a_device() {
    let dir = scratch("device");
    let null = dir.join("null");
    if !mknod_null(&null) {
        eprintln!("note: this process may not make device nodes; checked with a FIFO only");
        return;
    }
    let n = null.to_str().unwrap();
    // the report, the figure and the output all go to the device; no extension says the
    // format, so the output takes the series' streamable one (CSV) and the figure PNG
    let o = toposmooth(&["smooth", &fx(), "-o", n, "--report", n, "--plot", n, "--persistence", "2%"]);
    assert!(o.status.success(), "{}", text(&o));
    let m = std::fs::symlink_metadata(&null).unwrap();
    assert!(m.file_type().is_char_device(), "the device is not replaced by a regular file");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1, "nothing beside the device");
}

#[test]
fn dash_writes_the_output_on_stdout_and_the_summary_on_stderr() {
    let o = toposmooth(&["smooth", &fx(), "-o", "-", "--persistence", "2%"]);
    assert!(o.status.success(), "{}", text(&o));
    let out = String::from_utf8(o.stdout.clone()).unwrap();
    assert!(out.starts_with("date,input,output,u,role\n"), "{}", &out[..40.min(out.len())]);
    assert_eq!(out.lines().count(), 4755);
    let err = String::from_utf8(o.stderr.clone()).unwrap();
    assert!(err.contains("certified"), "{err}");
    assert!(err.contains("wrote standard output"), "{err}");
    // two outputs on one standard output are refused before any work
    let o = toposmooth(&["smooth", &fx(), "-o", "-", "--report", "-"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

#[test]
fn a_closed_pipe_ends_quietly_with_status_141() {
    let mut child =
        Command::new(bin()).args(["extrema", &fx()]).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    let mut stdout = child.stdout.take().unwrap();
    let mut first = [0u8; 16];
    std::io::Read::read_exact(&mut stdout, &mut first).unwrap();
    drop(stdout); // as `| head -c 16` does
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(141), "{}", text(&o));
    assert!(o.stderr.is_empty(), "no message, no panic: {}", String::from_utf8_lossy(&o.stderr));
}

/// A 300 × 300 noisy grid: a run that lasts long enough to be interrupted.
fn long_grid(dir: &Path) -> PathBuf {
    let v = common::uniform(7, 300 * 300);
    let rows: Vec<String> =
        v.chunks(300).map(|r| r.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(",")).collect();
    let p = dir.join("noise.csv");
    std::fs::write(&p, rows.join("\n") + "\n").unwrap();
    p
}

/// SIGINT cancels the run, which stops at its next check and exits with 130; SIGTERM ends it
/// at once as the signal does. Both remove the temporaries reserved before the work and write
/// nothing.
#[test]
fn an_interrupted_run_removes_its_temporaries_and_writes_nothing() {
    for signal in [libc::SIGINT, libc::SIGTERM] {
        let dir = scratch(&format!("interrupt-{signal}"));
        let input = long_grid(&dir);
        let out = dir.join("out").join("smoothed.vti");
        std::fs::create_dir(out.parent().unwrap()).unwrap();
        let report = out.with_file_name("run.json");
        let mut child = Command::new(bin())
            .args(["smooth", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--persistence", "1%"])
            .args(["--report", report.to_str().unwrap()])
            .stdout(Stdio::null())
            .stderr(Stdio::piped())
            .spawn()
            .unwrap();
        // the temporaries are reserved before any work: wait for both (or fail if the run ends first)
        while temporaries(out.parent().unwrap()).len() < 2 {
            assert!(child.try_wait().unwrap().is_none(), "the run ended before it could be interrupted");
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        // SAFETY: signalling our own child
        assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, signal) }, 0);
        let o = child.wait_with_output().unwrap();
        use std::os::unix::process::ExitStatusExt;
        if signal == libc::SIGINT {
            assert_eq!(o.status.code(), Some(130), "cancelled: {}", text(&o));
            assert!(String::from_utf8_lossy(&o.stderr).contains("error: cancelled"), "{}", text(&o));
        } else {
            assert_eq!(o.status.signal(), Some(signal), "ends as the signal ends a process: {:?}", o.status);
        }
        assert!(temporaries(out.parent().unwrap()).is_empty(), "{:?}", temporaries(out.parent().unwrap()));
        assert!(!out.exists() && !report.exists());
    }
}

/// SIGINT while the solver iterates on a 300 × 300 grid: the run stops at its next iteration
/// (exit 130, within the grace after which the tool ends itself as SIGINT does), leaving no
/// temporary and no output.
#[test]
fn sigint_during_the_solve_cancels_the_run_and_leaves_nothing() {
    use std::io::BufRead;
    let dir = scratch("interrupt-solve");
    let input = long_grid(&dir);
    let out = dir.join("out").join("smoothed.vti");
    std::fs::create_dir(out.parent().unwrap()).unwrap();
    let report = out.with_file_name("run.json");
    let mut child = Command::new(bin())
        .args(["smooth", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--persistence", "1%"])
        .args(["--report", report.to_str().unwrap()])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // off a terminal each finished stage is a line: the solve starts after the representative's
    let mut lines = std::io::BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = Vec::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        seen.push(line.clone());
        if line.starts_with("representative:") {
            break;
        }
    }
    assert!(seen.last().is_some_and(|l| l.starts_with("representative:")), "{seen:?}");
    // SAFETY: signalling our own child
    assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGINT) }, 0);
    let rest: Vec<String> = lines.map(|l| l.unwrap()).collect();
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{seen:?} {rest:?}");
    assert!(!rest.iter().any(|l| l.starts_with("solve:")), "the solve did not finish: {rest:?}");
    assert!(rest.iter().any(|l| l.contains("error: cancelled")), "{rest:?}");
    assert!(temporaries(out.parent().unwrap()).is_empty(), "{:?}", temporaries(out.parent().unwrap()));
    assert!(!out.exists() && !report.exists());
}

#[test]
fn stale_temporaries_are_removed_only_when_no_run_holds_them() {
    let dir = scratch("stale");
    let stale = dir.join(".toposmooth-999999-0123456789abcdef.tmp.csv");
    let held = dir.join(".toposmooth-999998-0123456789abcdef.tmp");
    std::fs::write(&stale, "left by a run killed with SIGKILL").unwrap();
    std::fs::write(&held, "a live run's").unwrap();
    let lock = std::fs::File::open(&held).unwrap();
    lock.lock().unwrap();
    // a link with a temporary's name is never followed nor removed
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "precious").unwrap();
    let link = dir.join(".toposmooth-999997-0123456789abcdef.tmp");
    std::os::unix::fs::symlink(&victim, &link).unwrap();
    let out = dir.join("fx.csv");
    let o = toposmooth(&["smooth", &fx(), "-o", out.to_str().unwrap(), "--persistence", "2%"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(!stale.exists(), "a temporary whose lock is free is removed");
    assert!(held.exists(), "a locked temporary is kept");
    assert!(std::fs::symlink_metadata(&link).is_ok());
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
    drop(lock);
}

#[test]
fn a_link_at_the_target_is_replaced_not_written_through() {
    let dir = scratch("target-link");
    let victim = dir.join("victim.csv");
    std::fs::write(&victim, "precious").unwrap();
    let out = dir.join("fx.csv");
    std::os::unix::fs::symlink(&victim, &out).unwrap();
    let o = toposmooth(&["smooth", &fx(), "-o", out.to_str().unwrap(), "--persistence", "2%"]);
    assert!(o.status.success(), "{}", text(&o));
    assert!(std::fs::symlink_metadata(&out).unwrap().is_file());
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious");
}

#[test]
fn long_and_non_utf8_output_names_work() {
    use std::os::unix::ffi::OsStrExt;
    let dir = scratch("names");
    let long = dir.join(format!("{}.csv", "x".repeat(251)));
    let a = dir.join(std::ffi::OsStr::from_bytes(b"r\xff.json"));
    let b = dir.join(std::ffi::OsStr::from_bytes(b"r\xfe.json"));
    let o = Command::new(bin())
        .args(["smooth", &fx(), "--persistence", "2%", "-o"])
        .arg(&long)
        .arg("--report")
        .arg(&a)
        .arg("--plot")
        .arg(dir.join(std::ffi::OsStr::from_bytes(b"p\xfe.png")))
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    assert!(std::fs::read_to_string(&long).unwrap().starts_with("date,"));
    assert!(std::fs::read_to_string(&a).unwrap().contains("\"certificate\""));
    assert!(!b.exists());
    assert!(temporaries(&dir).is_empty());
}

#[test]
fn outputs_that_cannot_be_written_are_refused_before_any_work() {
    let dir = scratch("before-work");
    let fx = fx();
    let out = dir.join("fx.csv");
    let o_ = out.to_str().unwrap();
    let (jpg, vti) = (dir.join("f.jpg"), dir.join("fx.vti"));
    let cases: [(&[&str], &str); 5] = [
        (&["-o", dir.to_str().unwrap()], "is a directory"),
        (&["-o", o_, "--report", "/nonexistent-toposmooth/r.json"], "does not exist"),
        (&["-o", o_, "--plot", jpg.to_str().unwrap()], "PNG"),
        (&["-o", vti.to_str().unwrap()], "written as .csv"),
        (&["-o", o_, "--isolines", "1000000000"], "0..=1000"),
    ];
    for (args, needle) in cases {
        let mut all = vec!["smooth", fx.as_str()];
        all.extend_from_slice(args);
        let o = toposmooth(&all);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {}", text(&o));
        assert!(text(&o).contains(needle), "{args:?}: `{needle}` not in {}", text(&o));
        assert!(!text(&o).contains("seconds:"), "{args:?}: refused before the work: {}", text(&o));
        assert!(!out.exists());
        assert!(temporaries(&dir).is_empty(), "{args:?}: {:?}", temporaries(&dir));
    }
    let o = toposmooth(&["smooth", &fx, "-o", o_, "--isolines", "5"]);
    assert_eq!(o.status.code(), Some(2), "a series has no isolines: {}", text(&o));
    let spot = dataset("spot.obj");
    let (mesh_out, fig) = (dir.join("spot.ply").display().to_string(), dir.join("spot.png").display().to_string());
    let o = toposmooth(&["smooth", &spot, "--array", "y", "-o", &mesh_out, "--plot", &fig, "--isolines", "5"]);
    assert_eq!(o.status.code(), Some(2), "a mesh figure has no isolines: {}", text(&o));
    assert!(text(&o).contains("isolines") && !text(&o).contains("seconds:"), "{}", text(&o));
    let o = toposmooth(&["bench", "--sizes", "1000000000000"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let o = toposmooth(&["bench", "--sizes", "100000x100000"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let o = toposmooth(&["bench", "--sizes", "4x4x4x4"]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(text(&o).contains("NXxNYxNZ (volume)"), "{}", text(&o));
}

#[test]
fn bench_runs_a_volume_through_the_active_set_iteration() {
    let o = toposmooth(&["bench", "--sizes", "12x10x8", "--solver", "active-set"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let row = String::from_utf8_lossy(&o.stdout).lines().find(|l| l.starts_with("| 12x10x8 |")).unwrap().to_string();
    let cells: Vec<&str> = row.split('|').map(str::trim).collect();
    // 13 kept (7 minima, 6 maxima); outer iterations with their conjugate-gradient count; the gap
    assert_eq!(cells[3], "13", "{row}");
    assert!(cells[5].contains(" CG)"), "{row}");
    let gap: f64 = cells[6].parse().unwrap();
    assert!(gap <= 1e-6, "{row}");
}

#[test]
fn progress_is_one_line_per_stage_off_a_terminal_and_quiet_silences_it() {
    let dir = scratch("progress");
    let out = dir.join("v.csv");
    let volcano = dataset("volcano_maunga_whau_61x87.csv");
    let o = toposmooth(&["smooth", &volcano, "-o", out.to_str().unwrap(), "--persistence", "5%"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let err = String::from_utf8(o.stderr.clone()).unwrap();
    let stages: Vec<&str> = err.lines().filter_map(|l| l.split_once(": ").map(|(s, _)| s)).collect();
    // the input's summary first, then each stage once, in the order they run; no spinner frames
    // (the complex is built only for the separatrix representative or --complex)
    assert_eq!(stages, ["read", "selection", "representative", "solve", "certificate", "write"], "{err}");
    assert!(err.lines().next().unwrap().contains("grid 87 × 61 (5307 vertices)"), "{err}");
    let solve = err.lines().find(|l| l.starts_with("solve: ")).unwrap();
    assert!(solve.contains("Solved after") && solve.contains("iterations"), "{solve}");
    assert!(!err.contains('\r') && !err.contains('\u{1b}'), "no terminal control off a terminal: {err:?}");
    // the summary on standard output is unchanged by progress
    assert!(String::from_utf8_lossy(&o.stdout).contains("certified"), "{}", text(&o));

    // --quiet, before or after the command: no stage lines; the summary stays
    for args in [vec!["--quiet", "smooth"], vec!["smooth", "-q"]] {
        let mut a = args.clone();
        a.extend([volcano.as_str(), "-o", out.to_str().unwrap(), "--persistence", "5%"]);
        let o = toposmooth(&a);
        assert_eq!(o.status.code(), Some(0), "{}", text(&o));
        let err = String::from_utf8(o.stderr.clone()).unwrap();
        assert!(!err.lines().any(|l| l.starts_with("solve: ") || l.starts_with("read: ")), "{err}");
        assert!(String::from_utf8_lossy(&o.stdout).contains("certified"), "{}", text(&o));
    }
}

#[test]
fn dash_reads_the_standard_input_and_a_fifo_input_is_read_once() {
    let dir = scratch("stdin");
    let out = dir.join("s.csv");
    let bytes = std::fs::read(fx()).unwrap();
    let mut child = Command::new(bin())
        .args(["-q", "smooth", "-", "-o", out.to_str().unwrap(), "--persistence", "8%"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::io::Write::write_all(&mut child.stdin.take().unwrap(), &bytes).unwrap();
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stdout).starts_with("standard input: 4754 samples"), "{}", text(&o));
    let from_file = dir.join("f.csv");
    let o = toposmooth(&["smooth", &fx(), "-o", from_file.to_str().unwrap(), "--persistence", "8%"]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(std::fs::read(&out).unwrap(), std::fs::read(&from_file).unwrap(), "stdin and the file give one output");
    // a bad standard input is named as such
    let mut child = Command::new(bin())
        .args(["smooth", "-", "-o", out.to_str().unwrap()])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    std::io::Write::write_all(&mut child.stdin.take().unwrap(), b"a,b\n").unwrap();
    let o = child.wait_with_output().unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("standard input:") && !err.contains("toposmooth-input-"), "{err}");
    // a FIFO is opened once: the writer below writes it once, and the run must not wait for more
    let fifo = dir.join("in.csv");
    mkfifo(&fifo);
    let (f, data) = (fifo.clone(), bytes.clone());
    let writer = std::thread::spawn(move || std::fs::write(&f, &data).unwrap());
    let o = toposmooth(&["-q", "extrema", fifo.to_str().unwrap()]);
    writer.join().unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stdout).contains("47 minima, 46 maxima"), "{}", text(&o));
}

// The defects of issue 18 as they were on cac0d08 (the commit before 676bbb5), each a case
// that fails there and passes now.

#[test]
fn links_planted_at_predictable_temporary_names_are_never_written_through() {
    // cac0d08 staged every output at `.NAME.PID.tmp`, opened with `File::create` (which follows
    // a link): a link planted there made the run overwrite the link's target, then renamed the
    // link over the output. The shell plants links at those names for its own PID, then `exec`s
    // the tool, which keeps that PID.
    let dir = scratch("planted-links");
    let victim = dir.join("victim.txt");
    std::fs::write(&victim, "precious").unwrap();
    let o = Command::new("sh")
        .current_dir(&dir)
        .arg("-c")
        .arg(r#"for n in fx.csv r.json; do ln -s victim.txt ".$n.$$.tmp" || exit 99; done; exec "$0" "$@""#)
        .arg(bin())
        .args(["smooth", &fx(), "-o", "fx.csv", "--report", "r.json", "--persistence", "2%"])
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert_eq!(std::fs::read_to_string(&victim).unwrap(), "precious", "the link's target is untouched");
    for (name, start) in [("fx.csv", "date,input,output,u,role\n"), ("r.json", "{")] {
        let p = dir.join(name);
        assert!(std::fs::symlink_metadata(&p).unwrap().is_file(), "{name} is a regular file, not a link");
        assert!(std::fs::read_to_string(&p).unwrap().starts_with(start), "{name}");
    }
    let links = std::fs::read_dir(&dir).unwrap().flatten().filter(|e| e.file_type().unwrap().is_symlink()).count();
    assert_eq!(links, 2, "the planted links are neither followed nor moved");
    assert!(temporaries(&dir).is_empty(), "{:?}", temporaries(&dir));
}

#[test]
fn a_report_to_a_device_node_leaves_the_device_in_place() {
    // cac0d08 renamed the report's temporary over the device: as root, `--report /dev/null`
    // replaced /dev/null with a regular file. The device here is made in a scratch directory.
    let dir = scratch("report-device");
    let null = dir.join("null");
    if !mknod_null(&null) {
        eprintln!("note: this process may not make device nodes; a_fifo_output_is_written_through covers FIFOs");
        return;
    }
    let out = dir.join("fx.csv");
    let o = toposmooth(&[
        "smooth",
        &fx(),
        "-o",
        out.to_str().unwrap(),
        "--report",
        null.to_str().unwrap(),
        "--persistence",
        "2%",
    ]);
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    let m = std::fs::symlink_metadata(&null).unwrap();
    assert!(m.file_type().is_char_device(), "the device is still a device: {:?}", m.file_type());
    assert!(std::fs::read_to_string(&out).unwrap().starts_with("date,"));
    let mut names: Vec<String> =
        std::fs::read_dir(&dir).unwrap().flatten().map(|e| e.file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    assert_eq!(names, ["fx.csv", "null"]);
}

#[test]
fn names_that_differ_only_in_invalid_utf8_bytes_get_their_own_files() {
    // cac0d08 named temporaries from the lossy UTF-8 form of the name: `a\xff.csv` and
    // `a\xfe.csv` shared `.a\u{fffd}.csv.PID.tmp`, so the first output received the second's
    // bytes and the second's rename failed (exit 3).
    use std::os::unix::ffi::OsStrExt;
    let dir = scratch("invalid-utf8-pair");
    let (csv, report) =
        (dir.join(std::ffi::OsStr::from_bytes(b"a\xff.csv")), dir.join(std::ffi::OsStr::from_bytes(b"a\xfe.csv")));
    let o = Command::new(bin())
        .args(["smooth", &fx(), "--persistence", "2%", "-o"])
        .arg(&csv)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    assert_eq!(o.status.code(), Some(0), "{}", text(&o));
    assert!(std::fs::read_to_string(&csv).unwrap().starts_with("date,input,output,u,role\n"), "the output's own bytes");
    let r = common::json(&report);
    assert_eq!(r["tool"], "toposmooth", "the report's own bytes");
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 2, "the two outputs and nothing else");
}

#[test]
fn the_input_summary_is_printed_while_the_work_has_not_ended() {
    // cac0d08 printed nothing on standard error, and its summary only at the end: a long run
    // was silent until it finished. The first line of standard error is the input's summary,
    // and it arrives while the run is still going (the run is waited for, never timed).
    use std::io::BufRead;
    let dir = scratch("summary-first");
    let input = long_grid(&dir);
    let out = dir.join("s.vti");
    let mut child = Command::new(bin())
        .args(["smooth", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--persistence", "1%"])
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut err = std::io::BufReader::new(child.stderr.take().unwrap());
    let mut first = String::new();
    err.read_line(&mut first).unwrap();
    let running = child.try_wait().unwrap().is_none();
    let solved_yet = out.exists();
    if running {
        // SAFETY: signalling our own child, not yet waited for
        assert_eq!(unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) }, 0);
        let _ = child.wait();
    }
    assert!(first.starts_with("read: ") && first.contains("grid 300 × 300 (90000 vertices)"), "{first:?}");
    assert!(running && !solved_yet, "the summary came before the work ended");
}

/// Off a terminal, a stage that runs for more than a second prints how far it is each time it
/// passes a further tenth: the solve of a 300 × 300 grid, its gap on a log scale to the target.
#[test]
fn a_long_solve_prints_its_fraction_in_a_log() {
    let dir = scratch("fraction-lines");
    let input = long_grid(&dir);
    let out = dir.join("smoothed.npz");
    let o = toposmooth(&["smooth", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--persistence", "1%"]);
    assert!(o.status.success(), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    let percents: Vec<u32> = stderr
        .lines()
        .filter_map(|l| l.strip_prefix("solve: ")?.split_once(" % after ").map(|(p, _)| p.parse::<u32>().unwrap()))
        .collect();
    assert!(!percents.is_empty(), "no fraction line: {stderr}");
    assert!(percents.iter().all(|p| p % 10 == 0 && *p <= 100), "{percents:?}");
    assert!(percents.windows(2).all(|w| w[0] < w[1]), "each line a further tenth: {percents:?}");
    assert!(stderr.lines().any(|l| l.starts_with("solve: ") && l.contains(" s (")), "the stage's own line: {stderr}");
}

/// Off a terminal a running stage is never silent for long: a line at least every 10 s
/// (`TOPOSMOOTH_LOG_EVERY` shortens it here) with how long it has run and what it last said.
#[test]
fn a_log_gets_a_line_from_a_running_stage_at_least_every_period() {
    let dir = scratch("heartbeat");
    let input = long_grid(&dir);
    let out = dir.join("smoothed.npz");
    let o = Command::new(bin())
        .env("TOPOSMOOTH_LOG_EVERY", "0.3")
        .args(["smooth", input.to_str().unwrap(), "-o", out.to_str().unwrap(), "--persistence", "1%"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    let beats: Vec<&str> = stderr.lines().filter(|l| l.starts_with("solve: running for ")).collect();
    assert!(beats.len() >= 2, "{stderr}");
    assert!(beats.iter().any(|l| l.contains("iteration")), "what the solver last said: {beats:?}");
}
