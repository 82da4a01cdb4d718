#!/usr/bin/env python3
"""Reference values for `mergesim::inference`, computed with scipy and statsmodels.

Writes tests/data/inference_reference.json (committed), which tests/inference_reference.rs
checks every Rust result against. python/tests/test_inference_reference.py recomputes it with
the installed libraries and asserts it equals the committed file, so CI checks the fixture
against scipy/statsmodels rather than against itself.

Pinned as in python/ci.sh: numpy 2.4.6, scipy 1.17.1, statsmodels 0.15.0.

    python3 scripts/inference_reference.py            # rewrites the fixture
    python3 scripts/inference_reference.py --check    # exit 1 if the fixture differs

Sources of each figure:
- Student t, normal, binomial: scipy.stats.t / norm / binom.
- paired t: scipy.stats.ttest_1samp(d, 0) and its confidence_interval(confidence).
- Wilcoxon: scipy.stats.wilcoxon(d) with its defaults (zero_method="wilcox", two-sided,
  correction=False, method="auto"). Each data set is built for one of scipy's "auto" branches
  (`expected_method`); the script asserts that the auto p-value equals the one scipy gives with
  that method named explicitly.
- exact McNemar: statsmodels.stats.contingency_tables.mcnemar(table, exact=True).
- Holm: statsmodels.stats.multitest.multipletests(p, method="holm")[1].
- Newcombe (1998) method 10 for paired proportions: statsmodels 0.15.0 has no paired
  version, so `ci` is computed here by `newcombe_paired_independent`, an independent, plain
  implementation of the published formulas on statsmodels' Wilson intervals
  (statsmodels.stats.proportion.proportion_confint(method="wilson")). Where the paper's phi is
  0, statsmodels' independent-samples Newcombe interval
  (confint_proportions_2indep(method="newcomb")) is the same formula and is recorded beside it
  as `statsmodels_phi0_ci` (the script asserts the two agree).
"""

from __future__ import annotations

import argparse
import json
import math
import os
import pathlib
import sys
import tempfile
import warnings

import numpy as np
import scipy
import scipy.stats as st
import statsmodels
from statsmodels.stats.contingency_tables import mcnemar
from statsmodels.stats.multitest import multipletests
from statsmodels.stats.proportion import confint_proportions_2indep, proportion_confint

REPO = pathlib.Path(__file__).resolve().parents[1]
FIXTURE = REPO / "tests" / "data" / "inference_reference.json"


def num(x) -> float | None:
    """A float for JSON; NaN becomes null (JSON has no NaN), ±inf the strings "inf"/"-inf"."""
    x = float(x)
    if math.isnan(x):
        return None
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return x


def differences() -> dict[str, tuple[list[float], str]]:
    """The fixed data sets of differences, each with the scipy "auto" branch it exercises."""
    rng = np.random.default_rng(20261202)
    distinct25 = [round(float(v), 4) for v in rng.normal(0.4, 1.0, 25)]
    assert len({abs(v) for v in distinct25}) == 25 and 0.0 not in distinct25
    ties_zeros30 = [round(float(v), 1) for v in rng.normal(0.2, 0.8, 30)]
    ties_zeros30[4] = 0.0
    ties_zeros30[17] = 0.0
    normal60 = [round(float(v), 3) for v in rng.normal(0.25, 1.0, 60)]
    normal60_ties_zeros = [round(float(v), 1) for v in rng.normal(-0.1, 0.6, 60)]
    normal60_ties_zeros[0] = 0.0
    normal60_ties_zeros[33] = 0.0
    large_effect20 = [round(float(v), 4) for v in rng.normal(3.0, 1.0, 20)]
    assert len({abs(v) for v in large_effect20}) == 20
    return {
        # n = 10, distinct |d|, no zeros: scipy's exact distribution.
        "exact_n10": (
            [1.83, -0.42, 2.71, 0.95, -1.37, 3.02, 0.18, 1.44, -0.66, 2.25],
            "exact",
        ),
        "exact_n25": (distinct25, "exact"),
        # A large effect: small p-values (relative accuracy in the tails).
        "large_effect_n20": (large_effect20, "exact"),
        # n = 12 with ties and zeros: scipy's exhaustive permutation test (n <= 13).
        "ties_zeros_n12": (
            [0.5, -0.25, 1.25, 0.0, 0.75, 0.5, -0.5, 1.0, 0.0, 0.25, 2.0, 0.5],
            "permutation",
        ),
        # n = 13, ties, no zero: still the permutation test.
        "ties_n13": (
            [0.1, 0.2, -0.2, -0.3, 0.4, 0.4, 0.4, 0.5, -0.6, 0.7, 0.8, 0.9, 1.0],
            "permutation",
        ),
        # 14 <= n <= 50 with ties and zeros: normal approximation.
        "ties_zeros_n30": (ties_zeros30, "asymptotic"),
        # n > 50: normal approximation whatever the ties.
        "normal_n60": (normal60, "asymptotic"),
        "normal_n60_ties_zeros": (normal60_ties_zeros, "asymptotic"),
        # All differences equal (sd = 0): scipy's t is inf and p 0.
        "all_equal_n8": ([0.3] * 8, "permutation"),
        # All differences 0: scipy's t and p are NaN (null here).
        "all_zero_n6": ([0.0] * 6, "permutation"),
        # The smallest sample a t-interval takes.
        "n2": ([1.0, 3.5], "exact"),
    }


def wilcoxon_with(d: list[float], method: str) -> float:
    if method == "permutation":
        return float(st.wilcoxon(d, method=st.PermutationMethod()).pvalue)
    return float(st.wilcoxon(d, method=method).pvalue)


def paired_t_entries(data) -> list[dict]:
    out = []
    for name, (d, _) in data.items():
        for confidence in [0.95] + ([0.90, 0.99] if name in ("exact_n10", "normal_n60") else []):
            res = st.ttest_1samp(d, 0.0)
            ci = res.confidence_interval(confidence)
            out.append(
                {
                    "data": name,
                    "confidence": confidence,
                    "n": len(d),
                    "mean": num(np.mean(d)),
                    "sd": num(np.std(d, ddof=1)),
                    "ci": [num(ci.low), num(ci.high)],
                    "t": num(res.statistic),
                    "df": num(res.df),
                    "p_two_sided": num(res.pvalue),
                }
            )
    return out


def wilcoxon_entries(data) -> list[dict]:
    out = []
    for name, (d, method) in data.items():
        res = st.wilcoxon(d)
        p_auto = float(res.pvalue)
        if not math.isnan(p_auto):
            p_named = wilcoxon_with(d, method)
            assert p_named == p_auto, (name, method, p_named, p_auto)
        out.append(
            {
                "data": name,
                "n_nonzero": int(np.count_nonzero(d)),
                "statistic": num(res.statistic),
                "p_two_sided": num(p_auto),
                "method": method,
            }
        )
    # scipy gives NaN for all zeros with n > 13; mergesim defines p = 1 (documented).
    res = st.wilcoxon([0.0] * 20)
    out.append(
        {
            "data": "all_zero_n20",
            "n_nonzero": 0,
            "statistic": num(res.statistic),
            "p_two_sided": num(res.pvalue),
            "method": "asymptotic",
        }
    )
    return out


TABLES = {
    # name: (both, only_first, only_second, neither)
    "moderate": (10, 5, 1, 20),
    "no_discordant": (7, 0, 0, 3),
    "balanced": (4, 6, 6, 4),
    "one_sided": (0, 9, 0, 41),
    "large": (100, 40, 25, 800),
    "large_discordant": (300, 1200, 1100, 400),
    "rare_events": (0, 3, 0, 197),
    # Fagerland, Lydersen & Laake (2017) ch. 8, Cavo et al. (2012).
    "cavo_2012": (59, 6, 16, 80),
    # Fagerland, Lydersen & Laake (2017) ch. 8, Bentur et al. (2009).
    "bentur_2009": (1, 1, 7, 12),
    # ad - bc < 0: the uncorrected negative phi.
    "negative_phi": (2, 8, 9, 1),
    # 0 <= ad - bc <= n/2: phi = 0.
    "small_positive_cross": (1, 2, 2, 5),
    "all_first_only": (0, 10, 0, 0),
}


def table_dict(t) -> dict:
    both, only_first, only_second, neither = t
    return {"both": both, "only_first": only_first, "only_second": only_second, "neither": neither}


def mcnemar_entries() -> list[dict]:
    out = []
    for name, t in TABLES.items():
        both, only_first, only_second, neither = t
        res = mcnemar([[both, only_first], [only_second, neither]], exact=True)
        out.append({"table_name": name, "table": table_dict(t), "p": num(res.pvalue)})
    return out


def phi_newcombe(t) -> float:
    """Newcombe (1998) paired method 10's continuity-corrected phi, as published."""
    a, b, c, d = (float(v) for v in t)
    n = a + b + c + d
    e, f, g, h = a + b, c + d, a + c, b + d
    if 0.0 in (e, f, g, h):
        return 0.0
    cross = a * d - b * c
    if cross > n / 2:
        numerator = cross - n / 2
    elif cross >= 0:
        numerator = 0.0
    else:
        numerator = cross
    return numerator / math.sqrt(e * f * g * h)


def newcombe_paired_independent(t, confidence: float) -> dict:
    """Newcombe (1998), Stat Med 17:2635, method 10, written from the paper's formulas.

    Independent of the Rust code: Wilson limits from statsmodels, z from scipy.
    """
    a, b, c, d = t
    n = a + b + c + d
    alpha = 1.0 - confidence
    l1, u1 = proportion_confint(a + b, n, alpha=alpha, method="wilson")
    l2, u2 = proportion_confint(a + c, n, alpha=alpha, method="wilson")
    p1, p2 = (a + b) / n, (a + c) / n
    theta = (b - c) / n
    phi = phi_newcombe(t)
    delta = math.sqrt((p1 - l1) ** 2 - 2 * phi * (p1 - l1) * (u2 - p2) + (u2 - p2) ** 2)
    epsilon = math.sqrt((u1 - p1) ** 2 - 2 * phi * (u1 - p1) * (p2 - l2) + (p2 - l2) ** 2)
    return {"n": n, "first": p1, "second": p2, "difference": theta, "ci": [theta - delta, theta + epsilon], "phi": phi}


def newcombe_entries() -> list[dict]:
    out = []
    for name, t in TABLES.items():
        for confidence in (0.95, 0.90):
            ours = newcombe_paired_independent(t, confidence)
            phi0 = None
            if ours["phi"] == 0.0:
                a, b, c, d = t
                n = a + b + c + d
                low, high = confint_proportions_2indep(
                    a + b, n, a + c, n, method="newcomb", compare="diff", alpha=1 - confidence
                )
                phi0 = [num(low), num(high)]
                assert all(math.isclose(x, y, rel_tol=1e-12, abs_tol=1e-15) for x, y in zip(phi0, ours["ci"])), (
                    name,
                    phi0,
                    ours["ci"],
                )
            out.append(
                {
                    "table_name": name,
                    "table": table_dict(t),
                    "confidence": confidence,
                    "n": ours["n"],
                    "first": num(ours["first"]),
                    "second": num(ours["second"]),
                    "difference": num(ours["difference"]),
                    "phi": num(ours["phi"]),
                    "ci": [num(v) for v in ours["ci"]],
                    "statsmodels_phi0_ci": phi0,
                }
            )
    return out


HOLM = {
    "four": [0.01, 0.04, 0.03, 0.005],
    "ties": [0.02, 0.02, 0.04, 0.001, 0.02],
    "capped": [0.5, 0.6, 0.9],
    "single": [0.3],
    "monotone_step": [0.001, 0.0125, 0.013, 0.2, 0.049, 0.0001, 0.7],
    "tiny": [1e-12, 3e-9, 2.5e-10, 0.04],
}


def holm_entries() -> list[dict]:
    return [
        {"name": name, "p_values": p, "adjusted": [num(v) for v in multipletests(p, method="holm")[1]]}
        for name, p in HOLM.items()
    ]


T_X = [0.0, 0.5, 1.96, 3.0, 10.0, 40.0, -2.5]
T_DF = [1, 2, 3, 7, 11, 59, 200, 1000, 100000]
UPPER_TAILS = [0.4, 0.05, 0.025, 0.005, 0.0005, 1e-8, 0.9]


def distribution_entries() -> dict:
    student_t = [
        {"x": x, "df": df, "cdf": num(st.t.cdf(x, df)), "sf": num(st.t.sf(x, df))}
        for df in T_DF
        for x in T_X
    ]
    student_t_quantile = [
        {"upper_tail": a, "df": df, "quantile": num(st.t.isf(a, df))} for df in T_DF for a in UPPER_TAILS
    ]
    normal = [
        {"x": x, "cdf": num(st.norm.cdf(x)), "sf": num(st.norm.sf(x))}
        for x in [-8.0, -3.0, -1.96, 0.0, 0.5, 1.96, 5.0, 10.0, 30.0]
    ]
    normal_quantile = [
        {"upper_tail": a, "quantile": num(st.norm.isf(a))} for a in UPPER_TAILS + [1e-5, 1e-12, 0.1]
    ]
    binomial = []
    for n, p in [(1, 0.5), (7, 0.5), (20, 0.5), (65, 0.5), (400, 0.5), (2300, 0.5), (30, 0.2), (500, 0.03)]:
        for k in sorted({0, 1, n // 10, n // 3, n // 2, n - 1, n}):
            binomial.append({"k": k, "n": n, "p": p, "cdf": num(st.binom.cdf(k, n, p))})
    return {
        "student_t": student_t,
        "student_t_quantile": student_t_quantile,
        "normal": normal,
        "normal_quantile": normal_quantile,
        "binomial_cdf": binomial,
    }


def compute() -> dict:
    # scipy warns (RuntimeWarning) on the deliberate edge cases: all-equal and all-zero
    # differences (zero variance, 0/0); their results are recorded as they come.
    warnings.filterwarnings("ignore", category=RuntimeWarning)
    data = differences()
    return {
        "generated_by": "scripts/inference_reference.py",
        "versions": {"numpy": np.__version__, "scipy": scipy.__version__, "statsmodels": statsmodels.__version__},
        "differences": {name: d for name, (d, _) in data.items()},
        "distributions": distribution_entries(),
        "paired_t": paired_t_entries(data),
        "wilcoxon": wilcoxon_entries(data),
        "mcnemar": mcnemar_entries(),
        "newcombe": newcombe_entries(),
        "holm": holm_entries(),
    }


def render(reference: dict) -> str:
    return json.dumps(reference, indent=1, allow_nan=False) + "\n"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with the committed fixture, write nothing")
    args = parser.parse_args()
    text = render(compute())
    if args.check:
        same = FIXTURE.read_text() == text
        print("fixture up to date" if same else f"{FIXTURE} differs from a fresh computation")
        return 0 if same else 1
    # Atomic: a temp file beside the fixture, then a rename.
    fd, tmp = tempfile.mkstemp(dir=FIXTURE.parent, prefix=".inference_reference.", suffix=".json")
    with os.fdopen(fd, "w") as f:
        f.write(text)
    os.replace(tmp, FIXTURE)
    print(f"wrote {FIXTURE.relative_to(REPO)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
