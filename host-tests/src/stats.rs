//! Confidence bounds on the Monte Carlo's rates: the Clopper–Pearson ("exact") interval of a
//! binomial proportion, the Beta distribution's quantiles found by bisection on its CDF
//! (`statrs`; its own inverse CDF hangs at Beta(1, 10⁷)), the campaign size an interval of a
//! given width needs, and a sample's nearest-rank quantiles as the examples print them.

use statrs::distribution::{Beta, ContinuousCDF};

/// The confidence level of every interval in the reports.
pub const CONFIDENCE: f64 = 0.95;

/// The two-sided Clopper–Pearson interval `[lo, hi]` at [`CONFIDENCE`] of `k` successes in `n`
/// trials; `None` when `n` is 0 or `k > n`.
///
/// ```
/// // No event in 1000 runs: the rate is below 3.7e-3 (two-sided 95 %).
/// let (lo, hi) = host_tests::stats::clopper_pearson(0, 1000).unwrap();
/// assert_eq!(lo, 0.0);
/// assert!((hi - (1.0 - 0.025_f64.powf(1e-3))).abs() < 1e-12);
/// ```
pub fn clopper_pearson(k: u64, n: u64) -> Option<(f64, f64)> {
    if n == 0 || k > n {
        return None;
    }
    let tail = (1.0 - CONFIDENCE) / 2.0;
    let (k, n) = (k as f64, n as f64);
    let quantile = |a: f64, b: f64, p: f64| Beta::new(a, b).ok().map(|d| quantile(&d, p));
    let lo = if k == 0.0 {
        0.0
    } else {
        quantile(k, n - k + 1.0, tail)?
    };
    let hi = if k == n {
        1.0
    } else {
        quantile(k + 1.0, n - k, 1.0 - tail)?
    };
    Some((lo, hi))
}

/// The `p`-quantile of `d`: bisection on its CDF down to adjacent floats.
fn quantile(d: &Beta, p: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    loop {
        let mid = lo + (hi - lo) / 2.0;
        if mid <= lo || mid >= hi {
            return mid;
        }
        if d.cdf(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
    }
}

/// The fewest trials whose interval is at most `width` wide when the observed rate is `rate`
/// (successes rounded to the nearest whole number); `None` beyond `limit` trials.
pub fn trials_for_width(rate: f64, width: f64, limit: u64) -> Option<u64> {
    let wide = |n: u64| {
        let k = (rate * n as f64).round() as u64;
        clopper_pearson(k.min(n), n).is_none_or(|(lo, hi)| hi - lo > width)
    };
    if wide(limit) {
        return None;
    }
    // The width shrinks with n (up to the rounding of k): bisect for the first narrow enough.
    let (mut lo, mut hi) = (1_u64, limit);
    while lo < hi {
        let mid = lo + (hi - lo) / 2;
        if wide(mid) {
            lo = mid + 1;
        } else {
            hi = mid;
        }
    }
    Some(lo)
}

/// The fewest event-free trials whose upper bound is at most `bound`.
pub fn trials_for_zero_events_below(bound: f64) -> u64 {
    // 1 − (α/2)^(1/n) ≤ bound  ⇔  n ≥ ln(α/2) / ln(1 − bound); checked against the interval.
    let tail = (1.0 - CONFIDENCE) / 2.0;
    let mut n = (tail.ln() / (1.0 - bound).ln()).ceil().max(1.0) as u64;
    while clopper_pearson(0, n).is_some_and(|(_, hi)| hi > bound) {
        n += 1;
    }
    n
}

/// `values`' minimum, nearest-rank quantiles at `at` (shares in (0, 1); 0.5 is the median) and
/// maximum on one line: "min 0.786, 1 % 0.790, median 1.000, max 1.210"; "none" when empty.
pub fn quantile_line(mut values: Vec<f64>, at: &[f64]) -> String {
    values.sort_by(f64::total_cmp);
    let (Some(first), Some(last)) = (values.first(), values.last()) else {
        return "none".into();
    };
    let rank = |p: f64| values[((values.len() - 1) as f64 * p).round() as usize];
    let mut line = format!("min {first:.3}");
    for &p in at {
        let name = if p == 0.5 {
            "median".into()
        } else {
            format!("{} %", p * 100.0)
        };
        line += &format!(", {name} {:.3}", rank(p));
    }
    line + &format!(", max {last:.3}")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantile_line_names_each_rank() {
        let v: Vec<f64> = (0..=100).map(f64::from).collect();
        assert_eq!(
            quantile_line(v, &[0.025, 0.5]),
            "min 0.000, 2.5 % 3.000, median 50.000, max 100.000"
        );
        assert_eq!(quantile_line(Vec::new(), &[0.5]), "none");
    }

    #[test]
    fn bounds_match_closed_forms_and_a_published_value() {
        // k = 0 and k = n have closed forms.
        for n in [1_u64, 10, 1000, 100_000, 10_000_000] {
            let (lo, hi) = clopper_pearson(0, n).unwrap();
            assert_eq!(lo, 0.0);
            let closed = -(0.025_f64.ln() / n as f64).exp_m1();
            // statrs' CDF is good to ≈ 4e-9 relative at n = 10⁷.
            assert!(
                (hi - closed).abs() < 1e-8 * closed,
                "{n}: {hi} against {closed}"
            );
            let (lo, hi) = clopper_pearson(n, n).unwrap();
            assert!((lo - 0.025_f64.powf(1.0 / n as f64)).abs() < 1e-10);
            assert_eq!(hi, 1.0);
        }
        // 5 of 10: [0.1871, 0.8129] (Clopper & Pearson's tables; R's binom.test).
        let (lo, hi) = clopper_pearson(5, 10).unwrap();
        assert!((lo - 0.187_086_3).abs() < 1e-6 && (hi - 0.812_913_7).abs() < 1e-6);
        assert_eq!(clopper_pearson(1, 0), None);
        assert_eq!(clopper_pearson(3, 2), None);
    }

    #[test]
    fn campaign_sizes_give_the_width_asked_for() {
        let n = trials_for_width(0.95, 0.02, 1_000_000).unwrap();
        let w = |n: u64| {
            let (lo, hi) = clopper_pearson((0.95 * n as f64).round() as u64, n).unwrap();
            hi - lo
        };
        // The normal approximation's (2·1.96)²·p(1 − p)/w² = 1825, a little below the exact.
        assert!(w(n) <= 0.02 && (1825..2000).contains(&n), "{n}");
        let z = trials_for_zero_events_below(1e-4);
        assert!(clopper_pearson(0, z).unwrap().1 <= 1e-4);
        assert!(clopper_pearson(0, z - 1).unwrap().1 > 1e-4);
        assert_eq!(trials_for_width(0.5, 1e-6, 1000), None);
    }
}
