//! One verdict per fit: what the material can be trusted for (energy,
//! highlight direction, gloss width) and what not, and for which θ_in,
//! derived from the per-incidence diagnostics ([`crate::Adequacy`]).
//! The summary, the report and the `.rad` header all print it.

use crate::adequacy::{ENERGY_TOLERANCE, GLOSS_WIDTH_TOLERANCE, PEAK_TOLERANCE_DEG};
use crate::summary::range;
use crate::{FitReport, FitResult};
use std::fmt;

/// Whether one aspect of the material can be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Trust {
    /// Every incidence that could judge it passed.
    Yes,
    /// At least one failed, or it cannot hold (a free scale's energy).
    No,
    /// Nothing could judge it (no diagnostics, no distinct peak).
    Unknown,
}

/// One aspect of the verdict.
#[derive(Debug, Clone, PartialEq)]
pub struct Aspect {
    /// `energy`, `highlight direction` or `gloss width`.
    pub what: &'static str,
    /// The judgement.
    pub trust: Trust,
    /// Why, with the numbers.
    pub why: String,
}

/// What a fitted material can be trusted for.
#[derive(Debug, Clone, PartialEq)]
pub struct Verdict {
    /// Energy, highlight direction and gloss width, in that order.
    pub aspects: Vec<Aspect>,
    /// The smallest and largest E1 over the incidences.
    pub e1: Option<(f64, f64)>,
    /// The fitted θ_in range, degrees.
    pub theta_in: (f64, f64),
    /// Fitted incidences.
    pub incidences: usize,
}

/// `θ_in a–b°` or `θ_in a°` over `reports`.
fn theta_span(reports: &[&FitReport]) -> String {
    let (lo, hi) = range(reports.iter().map(|r| r.theta_in));
    if hi - lo < 1e-9 {
        format!("θ_in {}°", short(lo))
    } else {
        format!("θ_in {}–{}°", short(lo), short(hi))
    }
}

/// A number in a few significant digits.
fn short(x: f64) -> String {
    let text = format!("{x:.2}");
    text.trim_end_matches('0').trim_end_matches('.').to_string()
}

/// "up to " before the largest of several deviations.
fn up_to(many: bool) -> &'static str {
    if many { "up to " } else { "" }
}

/// "at all 5 incidences" / "at the one incidence".
fn all_of(n: usize) -> String {
    if n == 1 {
        "at the one incidence".into()
    } else {
        format!("at all {n} incidences")
    }
}

/// An aspect judged by a per-incidence figure: `figure` gives the
/// incidence's deviation (`None`: cannot judge), `bad` decides, and
/// `describe` words the largest deviation (its flag: over several).
fn judge(
    what: &'static str,
    reports: &[FitReport],
    figure: impl Fn(&FitReport) -> Option<f64>,
    bad: impl Fn(f64) -> bool,
    describe: impl Fn(f64, bool) -> String,
    nothing: &str,
) -> Aspect {
    let judged: Vec<(&FitReport, f64)> = reports
        .iter()
        .filter_map(|r| figure(r).map(|x| (r, x)))
        .collect();
    let worst = |set: &[(&FitReport, f64)]| {
        set.iter()
            .map(|(_, x)| *x)
            .max_by(|a, b| a.abs().total_cmp(&b.abs()))
            .unwrap_or(0.0)
    };
    if judged.is_empty() {
        return Aspect {
            what,
            trust: Trust::Unknown,
            why: nothing.to_string(),
        };
    }
    let failed: Vec<(&FitReport, f64)> = judged.iter().copied().filter(|(_, x)| bad(*x)).collect();
    if failed.is_empty() {
        return Aspect {
            what,
            trust: Trust::Yes,
            why: format!(
                "{} {}",
                describe(worst(&judged), judged.len() > 1),
                all_of(judged.len())
            ),
        };
    }
    let where_: Vec<&FitReport> = failed.iter().map(|(r, _)| *r).collect();
    let count = if judged.len() == 1 {
        "at the one incidence".to_string()
    } else {
        format!("at {} of {} incidences", failed.len(), judged.len())
    };
    Aspect {
        what,
        trust: Trust::No,
        why: format!(
            "{} {count}, {}",
            describe(worst(&failed), failed.len() > 1),
            theta_span(&where_)
        ),
    }
}

impl FitResult {
    /// The verdict on this fit's material.
    pub fn verdict(&self) -> Verdict {
        let reports = &self.incidences;
        let checked = reports.iter().any(|r| r.adequacy.is_some());
        let not_checked = "not checked: --no-adequacy";
        let energy = if self.config.free_scale {
            Aspect {
                what: "energy",
                trust: Trust::No,
                why: "free scale: the reflectance is relative; give --rho or a beam integral"
                    .into(),
            }
        } else {
            judge(
                "energy",
                reports,
                |r| r.adequacy.as_ref()?.energy_ratio().map(|x| 1.0 / x - 1.0),
                |d| !(1.0 / (1.0 + ENERGY_TOLERANCE)..=1.0 + ENERGY_TOLERANCE).contains(&(1.0 + d)),
                |d, many| {
                    let side = if d >= 0.0 { "above" } else { "below" };
                    format!(
                        "model ρ/τ {}{:.1}% {side} the data's",
                        up_to(many),
                        100.0 * d.abs()
                    )
                },
                not_checked,
            )
        };
        let no_peak = if checked {
            "no distinct highlight in the data"
        } else {
            not_checked
        };
        let direction = judge(
            "highlight direction",
            reports,
            |r| r.adequacy.as_ref()?.peak_offset_deg,
            |d| d > PEAK_TOLERANCE_DEG,
            |d, many| format!("model peak {}{d:.1}° from the data's", up_to(many)),
            no_peak,
        );
        let width = judge(
            "gloss width",
            reports,
            |r| {
                let [data, model] = r.adequacy.as_ref()?.gloss_width_deg?;
                (data > 0.0).then(|| model / data - 1.0)
            },
            |d| d.abs() > GLOSS_WIDTH_TOLERANCE,
            |d, many| {
                let side = if d >= 0.0 { "wider" } else { "narrower" };
                format!(
                    "model highlight {}{:.0}% {side} than the data's",
                    up_to(many),
                    100.0 * d.abs()
                )
            },
            no_peak,
        );
        let e1s: Vec<f64> = reports.iter().filter_map(|r| r.e1).collect();
        let e1 = (!e1s.is_empty()).then(|| range(e1s.into_iter()));
        Verdict {
            aspects: vec![energy, direction, width],
            e1,
            theta_in: if reports.is_empty() {
                (0.0, 0.0)
            } else {
                range(reports.iter().map(|r| r.theta_in))
            },
            incidences: reports.len(),
        }
    }
}

impl Verdict {
    /// The aspects judged `trust`, as `name (why)`.
    fn list(&self, trust: Trust) -> Vec<String> {
        self.aspects
            .iter()
            .filter(|a| a.trust == trust)
            .map(|a| format!("{} ({})", a.what, a.why))
            .collect()
    }

    /// The θ_in range the material stands for.
    pub fn validity(&self) -> String {
        let (lo, hi) = self.theta_in;
        match self.incidences {
            0 => "no incidence fitted".into(),
            1 => format!(
                "valid at θ_in {}° only (one incidence fitted; other incidences are extrapolation)",
                short(lo)
            ),
            n => format!(
                "valid for θ_in {}–{}° ({n} incidences fitted; beyond them, extrapolation)",
                short(lo),
                short(hi)
            ),
        }
    }

    /// The verdict's parts, one per line: trusted, not trusted, not
    /// judged, misplaced light, θ_in validity.
    pub fn lines(&self) -> Vec<String> {
        let mut out = Vec::new();
        for (label, trust) in [("trust", Trust::Yes), ("do not trust", Trust::No)] {
            let items = self.list(trust);
            if !items.is_empty() {
                out.push(format!("{label}: {}", items.join("; ")));
            }
        }
        // Aspects nothing could judge, grouped by the reason.
        let mut unknown: Vec<(&str, Vec<&str>)> = Vec::new();
        for a in self.aspects.iter().filter(|a| a.trust == Trust::Unknown) {
            match unknown.iter_mut().find(|(why, _)| *why == a.why) {
                Some((_, names)) => names.push(a.what),
                None => unknown.push((&a.why, vec![a.what])),
            }
        }
        for (why, names) in unknown {
            out.push(format!("not judged: {} ({why})", names.join(", ")));
        }
        if let Some((lo, hi)) = self.e1 {
            out.push(if hi - lo < 5e-4 {
                format!("misplaced light (E1): {:.1}%", 100.0 * hi)
            } else {
                format!("misplaced light (E1): {:.1}–{:.1}%", 100.0 * lo, 100.0 * hi)
            });
        }
        out.push(self.validity());
        out
    }

    /// The one-phrase headline: what it is good for, what not.
    pub fn headline(&self) -> String {
        let names = |trust: Trust| -> Vec<&str> {
            self.aspects
                .iter()
                .filter(|a| a.trust == trust)
                .map(|a| a.what)
                .collect()
        };
        let (good, bad) = (names(Trust::Yes), names(Trust::No));
        match (good.is_empty(), bad.is_empty()) {
            (false, true) => format!("trust for {}", good.join(", ")),
            (false, false) => format!("trust for {}; not for {}", good.join(", "), bad.join(", ")),
            (true, false) => format!("do not trust for {}", bad.join(", ")),
            (true, true) => "not judged".into(),
        }
    }
}

impl fmt::Display for Verdict {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.lines().join("\n"))
    }
}
