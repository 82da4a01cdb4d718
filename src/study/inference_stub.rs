//! TEMPORARY stand-in for `mergesim::inference` (being written on another branch): the same
//! signatures with simple placeholder bodies (normal approximations), so the study compiles
//! before that library lands. To be deleted once `crate::inference` exists (the study then
//! imports it instead; nothing else changes).
#![allow(missing_docs, dead_code)]

use thiserror::Error;

#[derive(Debug, Error, Clone, PartialEq)]
pub enum InferenceError {
    #[error("{0}")]
    Invalid(String),
}

#[derive(Clone, Debug, PartialEq)]
pub struct PairedT {
    pub n: usize,
    pub mean: f64,
    pub sd: f64,
    pub ci: [f64; 2],
    pub confidence: f64,
    pub t: f64,
    pub df: f64,
    pub p_two_sided: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Wilcoxon {
    pub n_nonzero: usize,
    pub statistic: f64,
    pub p_two_sided: f64,
    pub method: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Discordance {
    pub both: u64,
    pub only_first: u64,
    pub only_second: u64,
    pub neither: u64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct PairedProportionDifference {
    pub n: u64,
    pub first: f64,
    pub second: f64,
    pub difference: f64,
    pub ci: [f64; 2],
    pub confidence: f64,
    pub method: String,
}

fn normal_sf(z: f64) -> f64 {
    // Abramowitz–Stegun 7.1.26 erfc approximation.
    let x = z.abs() / std::f64::consts::SQRT_2;
    let t = 1.0 / (1.0 + 0.327_591_1 * x);
    let poly = t
        * (0.254_829_592
            + t * (-0.284_496_736 + t * (1.421_413_741 + t * (-1.453_152_027 + t * 1.061_405_429))));
    0.5 * poly * (-x * x).exp()
}

pub fn paired_t(differences: &[f64], confidence: f64) -> Result<PairedT, InferenceError> {
    let n = differences.len();
    if n < 2 {
        return Err(InferenceError::Invalid(format!("n = {n}: need at least 2")));
    }
    let mean = differences.iter().sum::<f64>() / n as f64;
    let var = differences
        .iter()
        .map(|d| (d - mean).powi(2))
        .sum::<f64>()
        / (n as f64 - 1.0);
    let sd = var.sqrt();
    if sd == 0.0 {
        return Err(InferenceError::Invalid("zero variance".into()));
    }
    let se = sd / (n as f64).sqrt();
    let t = mean / se;
    let z = 1.96;
    Ok(PairedT {
        n,
        mean,
        sd,
        ci: [mean - z * se, mean + z * se],
        confidence,
        t,
        df: n as f64 - 1.0,
        p_two_sided: (2.0 * normal_sf(t)).min(1.0),
    })
}

pub fn wilcoxon_signed_rank(differences: &[f64]) -> Result<Wilcoxon, InferenceError> {
    let nz: Vec<f64> = differences.iter().copied().filter(|d| *d != 0.0).collect();
    let n = nz.len();
    if n == 0 {
        return Err(InferenceError::Invalid("every difference is zero".into()));
    }
    let mut order: Vec<usize> = (0..n).collect();
    order.sort_by(|&a, &b| nz[a].abs().total_cmp(&nz[b].abs()));
    let mut w_plus = 0.0;
    for (rank, &i) in order.iter().enumerate() {
        if nz[i] > 0.0 {
            w_plus += rank as f64 + 1.0;
        }
    }
    let nf = n as f64;
    let mu = nf * (nf + 1.0) / 4.0;
    let sigma = (nf * (nf + 1.0) * (2.0 * nf + 1.0) / 24.0).sqrt();
    Ok(Wilcoxon {
        n_nonzero: n,
        statistic: w_plus,
        p_two_sided: (2.0 * normal_sf((w_plus - mu) / sigma)).min(1.0),
        method: "placeholder normal approximation".into(),
    })
}

pub fn mcnemar_exact(table: &Discordance) -> f64 {
    let n = table.only_first + table.only_second;
    if n == 0 {
        return 1.0;
    }
    let k = table.only_first.min(table.only_second);
    let mut p = 0.0;
    let mut c = 1.0f64;
    for i in 0..=k {
        if i > 0 {
            c *= (n - i + 1) as f64 / i as f64;
        }
        p += c;
    }
    (2.0 * p * 0.5f64.powi(n as i32)).min(1.0)
}

pub fn newcombe_paired_difference(
    table: &Discordance,
    confidence: f64,
) -> Result<PairedProportionDifference, InferenceError> {
    let n = table.both + table.only_first + table.only_second + table.neither;
    if n == 0 {
        return Err(InferenceError::Invalid("no pair".into()));
    }
    let nf = n as f64;
    let first = (table.both + table.only_first) as f64 / nf;
    let second = (table.both + table.only_second) as f64 / nf;
    let difference = first - second;
    let half = 1.96 * ((first * (1.0 - first) + second * (1.0 - second)) / nf).sqrt();
    Ok(PairedProportionDifference {
        n,
        first,
        second,
        difference,
        ci: [(difference - half).max(-1.0), (difference + half).min(1.0)],
        confidence,
        method: "placeholder Wald".into(),
    })
}

pub fn holm(p: &[f64]) -> Vec<f64> {
    let m = p.len();
    let mut order: Vec<usize> = (0..m).collect();
    order.sort_by(|&a, &b| p[a].total_cmp(&p[b]));
    let mut adjusted = vec![0.0; m];
    let mut running = 0.0f64;
    for (k, &i) in order.iter().enumerate() {
        running = running.max(((m - k) as f64 * p[i]).min(1.0));
        adjusted[i] = running;
    }
    adjusted
}
