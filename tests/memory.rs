//! The memory budget: a run whose route (interior point or active set) is predicted past
//! `--memory-limit` is refused before the solve (exit 3, the estimate and the budget in the
//! message, nothing written, no temporary left), and the prediction is never below the peak
//! the run reaches by the end of its solve, on a series, grids, a tetrahedral mesh and volumes
//! (both routes).

mod common;

use common::{dataset, scratch, text, toposmooth};

/// No output and no temporary in `dir`.
fn nothing_left(dir: &std::path::Path) {
    let left: Vec<_> = std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert!(left.is_empty(), "nothing written, no temporary: {left:?}");
}

#[test]
fn a_run_predicted_past_its_budget_is_refused_before_the_solve_and_leaves_nothing() {
    let dir = scratch("memory-refused");
    let out = dir.join("piv.vti");
    let rep = dir.join("run.json");
    let piv = dataset("soapfilm_piv_vorticity_63x63.csv");
    let args = ["smooth", &piv, "--fill-missing", "-o", out.to_str().unwrap(), "--report", rep.to_str().unwrap()];
    let o = toposmooth(&[&args[..], &["--memory-limit", "4M"]].concat());
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("not enough memory: the interior-point route would need about"), "{stderr}");
    assert!(stderr.contains("over the memory budget of 4 MiB (the memory limit given)"), "{stderr}");
    assert!(stderr.contains("soapfilm_piv_vorticity_63x63.csv"), "the message names the file: {stderr}");
    nothing_left(&dir);
    // the same run with room succeeds, and says what it predicted
    let o = toposmooth(&[&args[..], &["--memory-limit", "2G"]].concat());
    assert!(o.status.success(), "{}", text(&o));
    let m = &common::json(&rep)["memory"];
    assert_eq!(m["budget"], 2u64 << 30);
    assert_eq!(m["budget_source"], "the memory limit given");
    assert!(m["predicted_peak"].as_u64().unwrap() > 4 << 20);
    let o = toposmooth(&[&args[..], &["--memory-limit", "lots"]].concat());
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
}

#[test]
fn the_prediction_is_never_below_the_peak_reached_by_the_end_of_the_solve() {
    let dir = scratch("memory-prediction");
    let cases: Vec<(String, Vec<&str>, &str)> = vec![
        (dataset("fx_eur_per_usd_daily_1999_2017.csv"), vec![], "fx.csv"),
        (dataset("karman_vortex_street_vorticity_65x513.csv"), vec!["--minima", "6", "--maxima", "6"], "k.npz"),
        (dataset("soapfilm_piv_vorticity_63x63.csv"), vec!["--fill-missing", "--order", "3"], "p.npz"),
        (dataset("spot_tets.vtu"), vec!["--solver", "structured"], "t.vtu"),
        (dataset("mri_anatomical_33x41x25.nii"), vec!["--solver", "structured"], "m.vti"),
        // the active-set route (the default on volumes)
        (dataset("mri_anatomical_33x41x25.nii"), vec![], "a.vti"),
        (
            dataset("abc_flow_noisy_32x32x32.vti"),
            vec!["--derive", "vorticity-magnitude", "--persistence", "10%", "--smooth-length", "0.03"],
            "abc.vti",
        ),
    ];
    for (input, extra, out) in cases {
        let (out, rep) = (dir.join(out), dir.join("run.json"));
        let mut args = vec!["smooth", &input, "-o", out.to_str().unwrap(), "--report", rep.to_str().unwrap()];
        args.extend(extra);
        let o = toposmooth(&args);
        assert!(o.status.success(), "{args:?}: {}", text(&o));
        let m = &common::json(&rep)["memory"];
        let (predicted, peak) = (m["predicted_peak"].as_u64(), m["peak_after_solve"].as_u64().unwrap());
        let predicted = predicted.unwrap_or_else(|| panic!("{input}: the route that ran predicted nothing"));
        assert!(peak > 0, "{input}");
        assert!(predicted >= peak, "{input}: predicted {predicted} B, reached {peak} B by the end of the solve");
    }
}

#[test]
fn an_active_set_run_predicted_past_its_budget_is_refused_before_the_solve() {
    let dir = scratch("memory-refused-active-set");
    let out = dir.join("m.vti");
    let mri = dataset("mri_anatomical_33x41x25.nii");
    // the run itself peaks at about 55 MiB and is predicted at about 58–63 MiB
    let o = toposmooth(&["smooth", &mri, "-o", out.to_str().unwrap(), "--memory-limit", "40M"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(stderr.contains("not enough memory: the active-set iteration would need about"), "{stderr}");
    assert!(stderr.contains("over the memory budget of 40 MiB"), "{stderr}");
    assert!(!stderr.contains("hand-over"), "refused, not handed to the interior-point route: {stderr}");
    nothing_left(&dir);
}

/// What the prediction does not foresee (here: a budget given above an address-space limit)
/// ends in the tool's allocator: a message, the temporaries removed, exit 3 — never an abort.
#[test]
fn an_allocation_refused_by_the_address_space_limit_ends_with_a_message_and_exit_3() {
    use std::os::unix::process::CommandExt;
    let dir = scratch("memory-rlimit");
    let out = dir.join("m.vti");
    let mri = dataset("mri_anatomical_33x41x25.nii");
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_toposmooth"));
    cmd.args(["smooth", &mri, "--solver", "structured", "--memory-limit", "100G", "-o", out.to_str().unwrap()]);
    // SAFETY: setrlimit only, in the child before exec
    unsafe {
        cmd.pre_exec(|| {
            let limit = libc::rlimit { rlim_cur: 256 << 20, rlim_max: 256 << 20 };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) == 0 {
                Ok(())
            } else {
                Err(std::io::Error::last_os_error())
            }
        });
    }
    let o = cmd.output().unwrap();
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert!(
        stderr.contains("error: not enough memory: an allocation of") && stderr.contains("bytes failed"),
        "{stderr}"
    );
    nothing_left(&dir);
}
