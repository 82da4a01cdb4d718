//! Every statistic of `mergesim::inference` against scipy 1.17.1 / statsmodels 0.15.0 on fixed
//! data: the fixture tests/data/inference_reference.json is written by
//! scripts/inference_reference.py (and checked against the live libraries by
//! python/tests/test_inference_reference.py).
//!
//! Tolerance: 1e-9 relative everywhere (the same formulas evaluated by different code; the
//! largest relative differences seen are printed with `--nocapture`). A reference value of
//! exactly 0 is compared absolutely (1e-15 for statistics, 1e-300 for a tail probability that
//! underflowed). Where scipy gives NaN (t-test of all-zero differences, Wilcoxon of all zeros
//! with n > 13) the fixture holds null and mergesim's documented value is asserted instead.

use std::cell::RefCell;
use std::collections::BTreeMap;

use mergesim::inference::distributions::{
    binomial_cdf, normal_cdf, normal_sf, normal_upper_quantile, student_t_cdf, student_t_sf,
    student_t_upper_quantile,
};
use mergesim::inference::{
    Discordance, WilcoxonMethod, holm, mcnemar_exact, newcombe_paired_difference, paired_t,
    wilcoxon_signed_rank,
};
use serde_json::Value;

const REL: f64 = 1e-9;

fn reference() -> Value {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/tests/data/inference_reference.json"
    );
    let text = std::fs::read_to_string(path).expect("the fixture is committed");
    serde_json::from_str(&text).expect("the fixture is JSON")
}

/// A number of the fixture: null is NaN (scipy's NaN), "inf"/"-inf" the infinities.
fn num(v: &Value) -> f64 {
    match v {
        Value::Null => f64::NAN,
        Value::String(s) if s == "inf" => f64::INFINITY,
        Value::String(s) if s == "-inf" => f64::NEG_INFINITY,
        other => other
            .as_f64()
            .unwrap_or_else(|| panic!("not a number: {other}")),
    }
}

fn numbers(v: &Value) -> Vec<f64> {
    v.as_array().expect("an array").iter().map(num).collect()
}

fn table(v: &Value) -> Discordance {
    let count = |k: &str| v[k].as_u64().expect("a count");
    Discordance {
        both: count("both"),
        only_first: count("only_first"),
        only_second: count("only_second"),
        neither: count("neither"),
    }
}

thread_local! {
    /// The largest relative difference seen per kind of figure (printed at the end).
    static WORST: RefCell<BTreeMap<String, (f64, String)>> = const { RefCell::new(BTreeMap::new()) };
}

/// `got` equals `expected` within `rel` relative (absolutely within `zero_abs` when the
/// reference is exactly 0; infinities must match exactly).
fn check(kind: &str, label: &str, got: f64, expected: f64, rel: f64, zero_abs: f64) {
    assert!(!expected.is_nan(), "{kind} {label}: reference is NaN");
    if expected.is_infinite() || got.is_infinite() {
        assert_eq!(got, expected, "{kind} {label}");
        return;
    }
    if expected == 0.0 {
        assert!(got.abs() <= zero_abs, "{kind} {label}: {got} vs 0");
        return;
    }
    let err = (got - expected).abs() / expected.abs();
    WORST.with(|w| {
        let mut w = w.borrow_mut();
        let worst = w.entry(kind.to_string()).or_insert((0.0, String::new()));
        if err > worst.0 {
            *worst = (err, label.to_string());
        }
    });
    assert!(
        err <= rel,
        "{kind} {label}: {got:e} vs {expected:e} (relative {err:e} > {rel:e})"
    );
}

fn print_worst() {
    WORST.with(|w| {
        for (kind, (err, label)) in w.borrow().iter() {
            println!("largest relative difference, {kind}: {err:.2e} ({label})");
        }
    });
}

#[test]
fn distributions_match_scipy() {
    let r = reference();
    let d = &r["distributions"];
    for e in d["student_t"].as_array().unwrap() {
        let (x, df) = (num(&e["x"]), num(&e["df"]));
        let label = format!("x={x} df={df}");
        check(
            "t cdf",
            &label,
            student_t_cdf(x, df),
            num(&e["cdf"]),
            REL,
            1e-300,
        );
        check(
            "t sf",
            &label,
            student_t_sf(x, df),
            num(&e["sf"]),
            REL,
            1e-300,
        );
    }
    for e in d["student_t_quantile"].as_array().unwrap() {
        let (a, df) = (num(&e["upper_tail"]), num(&e["df"]));
        let label = format!("upper tail {a} df={df}");
        check(
            "t quantile",
            &label,
            student_t_upper_quantile(a, df),
            num(&e["quantile"]),
            REL,
            0.0,
        );
    }
    for e in d["normal"].as_array().unwrap() {
        let x = num(&e["x"]);
        let label = format!("x={x}");
        check(
            "normal cdf",
            &label,
            normal_cdf(x),
            num(&e["cdf"]),
            REL,
            1e-300,
        );
        check(
            "normal sf",
            &label,
            normal_sf(x),
            num(&e["sf"]),
            REL,
            1e-300,
        );
    }
    for e in d["normal_quantile"].as_array().unwrap() {
        let a = num(&e["upper_tail"]);
        check(
            "normal quantile",
            &format!("{a}"),
            normal_upper_quantile(a),
            num(&e["quantile"]),
            REL,
            0.0,
        );
    }
    for e in d["binomial_cdf"].as_array().unwrap() {
        let (k, n, p) = (
            e["k"].as_u64().unwrap(),
            e["n"].as_u64().unwrap(),
            num(&e["p"]),
        );
        let label = format!("k={k} n={n} p={p}");
        check(
            "binomial cdf",
            &label,
            binomial_cdf(k, n, p),
            num(&e["cdf"]),
            REL,
            1e-300,
        );
    }
    print_worst();
}

#[test]
fn paired_t_matches_scipy_ttest_1samp() {
    let r = reference();
    for e in r["paired_t"].as_array().unwrap() {
        let name = e["data"].as_str().unwrap();
        let d = numbers(&r["differences"][name]);
        let confidence = num(&e["confidence"]);
        let label = format!("{name} at {confidence}");
        let got = paired_t(&d, confidence).unwrap();
        assert_eq!(got.n as u64, e["n"].as_u64().unwrap(), "{label}");
        assert_eq!(got.df, num(&e["df"]), "{label}");
        assert_eq!(got.confidence, confidence);
        check("t-test mean", &label, got.mean, num(&e["mean"]), REL, 1e-15);
        check("t-test sd", &label, got.sd, num(&e["sd"]), REL, 1e-15);
        let ci = numbers(&e["ci"]);
        check("t-interval", &label, got.ci[0], ci[0], REL, 1e-15);
        check("t-interval", &label, got.ci[1], ci[1], REL, 1e-15);
        if e["t"].is_null() {
            // All differences 0: scipy's 0/0 is NaN; mergesim's documented limit is t = 0, p = 1.
            assert!(d.iter().all(|&v| v == 0.0), "{label}");
            assert!(e["p_two_sided"].is_null());
            assert_eq!((got.t, got.p_two_sided), (0.0, 1.0), "{label}");
        } else {
            check("t statistic", &label, got.t, num(&e["t"]), REL, 1e-15);
            check(
                "t-test p",
                &label,
                got.p_two_sided,
                num(&e["p_two_sided"]),
                REL,
                1e-300,
            );
        }
    }
    print_worst();
}

#[test]
fn wilcoxon_matches_scipy() {
    let r = reference();
    for e in r["wilcoxon"].as_array().unwrap() {
        let name = e["data"].as_str().unwrap();
        let d = match name {
            "all_zero_n20" => vec![0.0; 20],
            _ => numbers(&r["differences"][name]),
        };
        let got = wilcoxon_signed_rank(&d).unwrap();
        let method = match e["method"].as_str().unwrap() {
            "exact" => WilcoxonMethod::Exact,
            "permutation" => WilcoxonMethod::Permutation,
            "asymptotic" => WilcoxonMethod::Normal,
            other => panic!("unknown method {other}"),
        };
        assert_eq!(got.method, method, "{name}");
        assert_eq!(
            got.n_nonzero as u64,
            e["n_nonzero"].as_u64().unwrap(),
            "{name}"
        );
        // The statistic is a sum of half-integer ranks: exact.
        assert_eq!(got.statistic, num(&e["statistic"]), "{name}");
        if e["p_two_sided"].is_null() {
            // All zeros, n > 13: scipy's NaN; mergesim's documented p = 1.
            assert_eq!(got.p_two_sided, 1.0, "{name}");
        } else {
            let kind = format!("wilcoxon p ({})", e["method"].as_str().unwrap());
            check(
                &kind,
                name,
                got.p_two_sided,
                num(&e["p_two_sided"]),
                REL,
                0.0,
            );
        }
    }
    print_worst();
}

#[test]
fn exact_mcnemar_matches_statsmodels() {
    let r = reference();
    for e in r["mcnemar"].as_array().unwrap() {
        let name = e["table_name"].as_str().unwrap();
        check(
            "mcnemar p",
            name,
            mcnemar_exact(&table(&e["table"])),
            num(&e["p"]),
            REL,
            0.0,
        );
    }
    print_worst();
}

#[test]
fn newcombe_matches_the_published_formulas() {
    let r = reference();
    let mut checked_against_statsmodels = 0;
    for e in r["newcombe"].as_array().unwrap() {
        let name = e["table_name"].as_str().unwrap();
        let confidence = num(&e["confidence"]);
        let label = format!("{name} at {confidence}");
        let got = newcombe_paired_difference(&table(&e["table"]), confidence).unwrap();
        assert_eq!(got.n, e["n"].as_u64().unwrap());
        check(
            "newcombe proportions",
            &label,
            got.first,
            num(&e["first"]),
            REL,
            1e-15,
        );
        check(
            "newcombe proportions",
            &label,
            got.second,
            num(&e["second"]),
            REL,
            1e-15,
        );
        check(
            "newcombe difference",
            &label,
            got.difference,
            num(&e["difference"]),
            REL,
            1e-15,
        );
        // The independent Python implementation of the paper's formulas.
        let ci = numbers(&e["ci"]);
        check("newcombe ci (python)", &label, got.ci[0], ci[0], REL, 1e-15);
        check("newcombe ci (python)", &label, got.ci[1], ci[1], REL, 1e-15);
        // statsmodels, where phi = 0 (its independent-samples Newcombe interval).
        if !e["statsmodels_phi0_ci"].is_null() {
            let sm = numbers(&e["statsmodels_phi0_ci"]);
            check(
                "newcombe ci (statsmodels, phi 0)",
                &label,
                got.ci[0],
                sm[0],
                REL,
                1e-15,
            );
            check(
                "newcombe ci (statsmodels, phi 0)",
                &label,
                got.ci[1],
                sm[1],
                REL,
                1e-15,
            );
            checked_against_statsmodels += 1;
        }
    }
    assert!(
        checked_against_statsmodels >= 8,
        "{checked_against_statsmodels}"
    );
    print_worst();
}

#[test]
fn holm_matches_statsmodels_multipletests() {
    let r = reference();
    for e in r["holm"].as_array().unwrap() {
        let name = e["name"].as_str().unwrap();
        let got = holm(&numbers(&e["p_values"]));
        let expected = numbers(&e["adjusted"]);
        assert_eq!(got.len(), expected.len(), "{name}");
        for (g, x) in got.iter().zip(&expected) {
            check("holm", name, *g, *x, REL, 0.0);
        }
    }
    print_worst();
}

#[test]
fn the_fixture_covers_every_branch() {
    // The data sets exercise each of scipy's Wilcoxon branches and both t edge cases, so a
    // fixture regenerated with fewer cases fails here rather than testing less.
    let r = reference();
    let methods: Vec<&str> = r["wilcoxon"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e["method"].as_str().unwrap())
        .collect();
    for m in ["exact", "permutation", "asymptotic"] {
        assert!(methods.iter().filter(|&&x| x == m).count() >= 2, "{m}");
    }
    let tables: Vec<Discordance> = r["mcnemar"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| table(&e["table"]))
        .collect();
    assert!(tables.iter().any(|t| t.discordant() == 0));
    assert!(
        r["paired_t"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e["t"] == "inf")
    );
    assert!(
        r["paired_t"]
            .as_array()
            .unwrap()
            .iter()
            .any(|e| e["t"].is_null())
    );
    assert_eq!(r["versions"]["scipy"], "1.17.1");
    assert_eq!(r["versions"]["statsmodels"], "0.15.0");
}
