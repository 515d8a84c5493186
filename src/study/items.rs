//! The list flags of `mbd study`: `--integrator LIST`, `--alpha LIST`, `--steps LIST` and
//! `--dt LIST`, parsed into typed items; a list that is not understood is a [`UsageError`].

use crate::settings::{self, Method, Request};
use std::fmt;

/// A list flag of `mbd study` that is not understood (a usage error, exit 2). `Display` is the
/// message the command line prints after `error: `.
#[derive(Clone, Debug, PartialEq)]
pub enum UsageError {
    /// An empty list or an empty item (`--steps 100,,200`).
    EmptyItem { flag: String, list: String },
    /// A `--steps` item that is not a whole number of at least 1.
    StepCount { item: String },
    /// A `--dt` item that is not a positive number of seconds.
    Dt { item: String },
    /// A `--dt` that gives no whole number of steps in 1..=1e9 over the run.
    DtDoesNotFit { dt: f64, until: f64, steps: f64 },
    /// An `--alpha` item that is not an HHT alpha.
    Alpha { item: String },
    /// An integrator item's parameter that is not a number (`hht:x`).
    NotANumber {
        item: String,
        what: &'static str,
        text: String,
    },
    /// An integrator item's parameter outside its range (`hht:0.5`).
    OutOfRange {
        item: String,
        what: &'static str,
        value: f64,
        range: &'static str,
    },
    /// `fet:...`: time finite elements take no parameter.
    FetParameter { item: String },
    /// Not an integrator item at all.
    UnknownIntegrator { item: String },
}

impl fmt::Display for UsageError {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        match self {
            UsageError::EmptyItem { flag, list } => write!(
                f,
                "{flag} takes a comma-separated list without empty items, got `{list}`"
            ),
            UsageError::StepCount { item } => write!(
                f,
                "--steps: `{item}` is not a whole number of steps of at least 1"
            ),
            UsageError::Dt { item } => {
                write!(f, "--dt: `{item}` is not a positive number of seconds")
            }
            UsageError::DtDoesNotFit { dt, until, steps } => write!(
                f,
                "--dt {dt} s does not fit the run's {until} s (round(until / dt) = {steps})"
            ),
            UsageError::Alpha { item } => {
                write!(f, "--alpha: `{item}` is not an HHT alpha in [-1/3, 0]")
            }
            UsageError::NotANumber { item, what, text } => {
                write!(f, "`{item}`: {what} `{text}` is not a number")
            }
            UsageError::OutOfRange {
                item,
                what,
                value,
                range,
            } => write!(f, "`{item}`: {what} = {value} is outside {range}"),
            UsageError::FetParameter { item } => write!(f, "`{item}`: fet takes no parameter"),
            UsageError::UnknownIntegrator { item } => write!(
                f,
                "unknown integrator `{item}`; the items are hht, hht:ALPHA (e.g. hht:-0.3), generalized-alpha, generalized-alpha:RHO_INF (e.g. generalized-alpha:0.5) and fet"
            ),
        }
    }
}

impl std::error::Error for UsageError {}

/// One item of `--integrator LIST`, kept as written for the CSV.
#[derive(Clone, Debug, PartialEq)]
pub struct IntegratorItem {
    /// As written: `hht`, `hht:-0.3`, `generalized-alpha:0.5`, `fet`.
    pub text: String,
    pub integrator: Method,
    /// HHT alpha (`hht:ALPHA`), in [-1/3, 0]; `None`: the model's.
    pub alpha: Option<f64>,
    /// Generalized-alpha spectral radius at infinity (`generalized-alpha:RHO`), in [0, 1].
    pub rho_inf: Option<f64>,
}

impl IntegratorItem {
    /// Parses `hht`, `hht:ALPHA`, `generalized-alpha`, `generalized-alpha:RHO_INF` or `fet`.
    pub fn parse(text: &str) -> Result<IntegratorItem, UsageError> {
        let text = text.trim();
        let (name, arg) = match text.split_once(':') {
            Some((n, a)) => (n, Some(a)),
            None => (text, None),
        };
        let item = |integrator, alpha, rho_inf| IntegratorItem {
            text: text.to_string(),
            integrator,
            alpha,
            rho_inf,
        };
        match (name, arg) {
            ("hht", a) => {
                let alpha = a
                    .map(|a| bounded(text, "alpha", a, settings::ALPHA))
                    .transpose()?;
                Ok(item(Method::Hht, alpha, None))
            }
            ("generalized-alpha" | "generalized_alpha", a) => {
                let rho = a
                    .map(|a| bounded(text, "rho_inf", a, settings::RHO_INF))
                    .transpose()?;
                Ok(item(Method::GeneralizedAlpha, None, rho))
            }
            ("fet", None) => Ok(item(Method::Fet, None, None)),
            ("fet", Some(_)) => Err(UsageError::FetParameter {
                item: text.to_string(),
            }),
            _ => Err(UsageError::UnknownIntegrator {
                item: text.to_string(),
            }),
        }
    }

    /// The items of `--integrator LIST`.
    pub fn parse_list(list: &str) -> Result<Vec<IntegratorItem>, UsageError> {
        split_list(list, "--integrator")?
            .into_iter()
            .map(IntegratorItem::parse)
            .collect()
    }

    /// `base` with this integrator setting.
    pub fn request(&self, base: &Request) -> Request {
        let mut o = base.clone();
        o.method = Some(self.integrator);
        o.alpha = self.alpha.or(base.alpha);
        o.rho_inf = self.rho_inf.or(base.rho_inf);
        o
    }
}

fn bounded(
    item: &str,
    what: &'static str,
    text: &str,
    range: settings::Range,
) -> Result<f64, UsageError> {
    let v: f64 = text.trim().parse().map_err(|_| UsageError::NotANumber {
        item: item.to_string(),
        what,
        text: text.to_string(),
    })?;
    if !range.contains(v) {
        return Err(UsageError::OutOfRange {
            item: item.to_string(),
            what,
            value: v,
            range: range.text,
        });
    }
    Ok(v)
}

/// The items of a comma-separated list (`--steps 100,200`); an empty list or item is an error.
pub fn split_list<'t>(text: &'t str, flag: &str) -> Result<Vec<&'t str>, UsageError> {
    let items: Vec<&str> = text.split(',').map(str::trim).collect();
    if items.iter().any(|i| i.is_empty()) {
        return Err(UsageError::EmptyItem {
            flag: flag.to_string(),
            list: text.to_string(),
        });
    }
    Ok(items)
}

/// The HHT alphas of `--alpha LIST`, each in [`settings::ALPHA`] (no allowance above 0).
pub fn parse_alphas(list: &str) -> Result<Vec<f64>, UsageError> {
    let range = settings::ALPHA;
    split_list(list, "--alpha")?
        .into_iter()
        .map(|s| match s.parse::<f64>() {
            Ok(v) if (range.min - 1e-12..=range.max).contains(&v) => Ok(v),
            _ => Err(UsageError::Alpha {
                item: s.to_string(),
            }),
        })
        .collect()
}

/// The runs' steps: `--steps LIST` (counts; dt = until / N) or `--dt LIST` (seconds;
/// N = round(until / dt)). Either way every run ends at the model's end time.
#[derive(Clone, Debug, PartialEq)]
pub enum StepList {
    Counts(Vec<usize>),
    Dt(Vec<f64>),
}

impl StepList {
    pub fn parse_counts(text: &str) -> Result<StepList, UsageError> {
        let counts = split_list(text, "--steps")?
            .into_iter()
            .map(|s| match s.parse::<usize>() {
                Ok(n) if n >= 1 => Ok(n),
                _ => Err(UsageError::StepCount {
                    item: s.to_string(),
                }),
            })
            .collect::<Result<_, _>>()?;
        Ok(StepList::Counts(counts))
    }

    pub fn parse_dt(text: &str) -> Result<StepList, UsageError> {
        let steps = split_list(text, "--dt")?
            .into_iter()
            .map(|s| match s.parse::<f64>() {
                Ok(d) if d > 0.0 && d.is_finite() => Ok(d),
                _ => Err(UsageError::Dt {
                    item: s.to_string(),
                }),
            })
            .collect::<Result<_, _>>()?;
        Ok(StepList::Dt(steps))
    }

    /// Step counts for a run that ends at `until`.
    pub fn counts(&self, until: f64) -> Result<Vec<usize>, UsageError> {
        match self {
            StepList::Counts(n) => Ok(n.clone()),
            StepList::Dt(dts) => dts
                .iter()
                .map(|&dt| {
                    let n = (until / dt).round();
                    if (1.0..=1e9).contains(&n) {
                        Ok(n as usize)
                    } else {
                        Err(UsageError::DtDoesNotFit {
                            dt,
                            until,
                            steps: n,
                        })
                    }
                })
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integrator_items_parse_as_written() {
        let hht = IntegratorItem::parse("hht:-0.3").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!((hht.integrator, hht.alpha), (Method::Hht, Some(-0.3)));
        assert_eq!(hht.text, "hht:-0.3");
        let ga = IntegratorItem::parse("generalized-alpha:0.5").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (ga.integrator, ga.rho_inf),
            (Method::GeneralizedAlpha, Some(0.5))
        );
        assert!(IntegratorItem::parse("fet").is_ok());
        for bad in [
            "hht:0.5",
            "hht:x",
            "rk4",
            "generalized-alpha:2",
            "fet:1",
            "",
        ] {
            assert!(IntegratorItem::parse(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn step_lists_keep_the_end_time() {
        let dt = StepList::parse_dt("0.1,0.05").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(dt.counts(1.0), Ok(vec![10, 20]));
        assert!(StepList::parse_dt("0.1,,0.05").is_err());
        assert!(StepList::parse_counts("0").is_err());
        assert!(StepList::parse_dt("5")
            .map(|d| d.counts(1.0).is_err())
            .unwrap_or(false));
    }

    #[test]
    fn alphas_are_hht_alphas() {
        assert_eq!(parse_alphas("0,-0.1"), Ok(vec![0.0, -0.1]));
        for bad in ["0.1", "-0.5", "x", "0,,1"] {
            assert!(parse_alphas(bad).is_err(), "{bad}");
        }
    }
}
