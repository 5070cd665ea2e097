//! Which share of a render a machine takes, and which renders can be split.
//!
//! - `--part K/N` (0 ≤ K < N): the K-th of N parts. Without adaptive
//!   sampling a part is a range of sample indices (or SPPM iterations):
//!   part K of a render of S samples takes ⌊K·S/N⌋..⌊(K+1)·S/N⌋. With
//!   adaptive sampling a part is every N-th row from row K, with all S
//!   samples: whether a pixel takes its next sample depends on its earlier
//!   samples, which a part starting at sample A > 0 would not have; rows
//!   carry their whole history, so their parts merge exactly.
//! - `--part auto`: K and N from the scheduler: Slurm job arrays
//!   (SLURM_ARRAY_TASK_ID − SLURM_ARRAY_TASK_MIN of SLURM_ARRAY_TASK_COUNT),
//!   or Kubernetes Indexed Jobs (JOB_COMPLETION_INDEX), which do not say how
//!   many parts there are: give N as `--part auto/N`.
//! - `--samples A..B`: sample indices A..B of every row (not with adaptive
//!   sampling unless A = 0).
//!
//! Not splittable: renders to a time limit (a part must know its samples)
//! and SPPM with the per-pixel radius update (each iteration depends on the
//! ones before; use `radius_schedule = "global"`).

use super::FarmError;
use crate::integrator::{RowSet, Share};
use crate::settings::{IntegratorKind, RadiusSchedule, RenderSettings};
use std::ops::Range;

/// A share as the command line asks for it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum PartRequest {
    /// Part `part` of `parts` (0-based).
    Part {
        /// Which part, `0..parts`.
        part: u32,
        /// How many parts the render is split into (at least 1).
        parts: u32,
    },
    /// Sample indices (or iterations) `A..B`.
    Samples(Range<u32>),
}

impl PartRequest {
    /// Parses `--part`: `K/N`, `auto` or `auto/N`, `auto` read from `env`
    /// (a lookup of environment variables, `std::env::var` in the CLI).
    pub fn parse_part(text: &str, env: impl Fn(&str) -> Option<String>) -> Result<Self, FarmError> {
        let bad = |message: String| FarmError::Argument { flag: "--part", message };
        let (index, count) = text.split_once('/').map_or((text, None), |(k, n)| (k, Some(n)));
        let count = count
            .map(|n| {
                n.trim()
                    .parse::<u32>()
                    .map_err(|_| bad(format!("expected K/N, auto or auto/N with whole numbers (found {text:?})")))
            })
            .transpose()?;
        let (part, parts) = if index.trim() == "auto" {
            auto_part(count, &env)?
        } else {
            let part = index
                .trim()
                .parse::<u32>()
                .map_err(|_| bad(format!("expected K/N, auto or auto/N with whole numbers (found {text:?})")))?;
            let parts = count.ok_or_else(|| bad(format!("expected K/N, e.g. 0/4 (found {text:?})")))?;
            (part, parts)
        };
        if parts == 0 || part >= parts {
            return Err(bad(format!("part {part} of {parts} does not exist (parts are 0 to N−1)")));
        }
        Ok(PartRequest::Part { part, parts })
    }

    /// Parses `--samples A..B` (A < B).
    pub fn parse_samples(text: &str) -> Result<Self, FarmError> {
        let bad = |message: String| FarmError::Argument {
            flag: "--samples",
            message,
        };
        let (a, b) = text.split_once("..").ok_or_else(|| {
            bad(format!(
                "expected a range A..B of sample indices, e.g. 0..64 (found {text:?})"
            ))
        })?;
        let parse = |v: &str| {
            v.trim()
                .parse::<u32>()
                .map_err(|_| bad(format!("expected whole numbers A..B below 2³² (found {text:?})")))
        };
        let (start, end) = (parse(a)?, parse(b)?);
        if start >= end {
            return Err(bad(format!("the range {start}..{end} is empty (A must be below B)")));
        }
        Ok(PartRequest::Samples(start..end))
    }
}

/// K and N from the scheduler's environment.
fn auto_part(count: Option<u32>, env: &impl Fn(&str) -> Option<String>) -> Result<(u32, u32), FarmError> {
    let bad = |message: String| FarmError::Argument {
        flag: "--part auto",
        message,
    };
    let number = |name: &str| -> Result<Option<u32>, FarmError> {
        env(name)
            .map(|v| {
                v.trim()
                    .parse::<u32>()
                    .map_err(|_| bad(format!("{name}={v:?} is not a whole number")))
            })
            .transpose()
    };
    let slurm = number("SLURM_ARRAY_TASK_ID")?;
    let kubernetes = number("JOB_COMPLETION_INDEX")?;
    match (slurm, kubernetes) {
        (Some(_), Some(_)) => Err(bad(
            "both SLURM_ARRAY_TASK_ID and JOB_COMPLETION_INDEX are set; give the part as K/N".into(),
        )),
        (Some(task), None) => {
            if let Some(step) = number("SLURM_ARRAY_TASK_STEP")?.filter(|&s| s != 1) {
                return Err(bad(format!(
                    "the job array steps by {step}; submit it as --array=0-{{N-1}} (step 1)"
                )));
            }
            let first = number("SLURM_ARRAY_TASK_MIN")?.unwrap_or(0);
            let tasks = number("SLURM_ARRAY_TASK_COUNT")?;
            let parts = match (tasks, count) {
                (Some(tasks), Some(count)) if tasks != count => {
                    return Err(bad(format!("the job array has {tasks} tasks but --part says {count} parts")));
                }
                (Some(tasks), _) => tasks,
                (None, Some(count)) => count,
                (None, None) => return Err(bad("SLURM_ARRAY_TASK_COUNT is not set; give the count as auto/N".into())),
            };
            let part = task
                .checked_sub(first)
                .ok_or_else(|| bad(format!("SLURM_ARRAY_TASK_ID {task} is below SLURM_ARRAY_TASK_MIN {first}")))?;
            Ok((part, parts))
        }
        (None, Some(index)) => {
            let parts = count.ok_or_else(|| {
                bad("JOB_COMPLETION_INDEX says which part but not how many: give --part auto/N (the Job's completions)".into())
            })?;
            Ok((index, parts))
        }
        (None, None) => Err(bad(
            "neither SLURM_ARRAY_TASK_ID (a Slurm job array) nor JOB_COMPLETION_INDEX (a Kubernetes Indexed Job) is set".into(),
        )),
    }
}

/// The share `request` asks of a render with `settings`, or why it cannot
/// be split so.
pub fn plan_share(settings: &RenderSettings, request: &PartRequest) -> Result<Share, FarmError> {
    let cannot = |message: &str| Err(FarmError::CannotSplit(message.to_string()));
    if settings.time_limit.is_some() {
        return cannot("a render to a time limit (--time) cannot be split: each part must know which samples it takes");
    }
    if settings.integrator == IntegratorKind::Sppm && settings.sppm.radius_schedule == RadiusSchedule::PerPixel {
        return cannot(
            "SPPM with the per-pixel radius update cannot be split: each iteration depends on the ones before. \
             Use --radius-schedule global (radius_schedule = \"global\" in [render]), whose iterations are independent",
        );
    }
    let adaptive = settings.adaptive_threshold.is_some() && settings.integrator != IntegratorKind::Sppm;
    match *request {
        PartRequest::Part { part, parts } => {
            let Some(total) = settings.samples_per_pixel else {
                return cannot("a part needs a sample count (--spp) to take its share of");
            };
            if adaptive {
                return Ok(Share {
                    samples: 0..total,
                    rows: RowSet {
                        first: part,
                        step: parts,
                    },
                });
            }
            let bound = |k: u32| (k as u64 * total as u64 / parts as u64) as u32;
            Ok(Share {
                samples: bound(part)..bound(part + 1),
                rows: RowSet::ALL,
            })
        }
        PartRequest::Samples(ref range) => {
            if adaptive && range.start > 0 {
                return Err(FarmError::CannotSplit(format!(
                    "adaptive sampling cannot render samples {}..{} alone: whether a pixel takes a sample depends on \
                     its samples before {}. Split adaptive renders with --part K/N, which splits them by rows",
                    range.start, range.end, range.start
                )));
            }
            Ok(Share {
                samples: range.clone(),
                rows: RowSet::ALL,
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::HashMap;

    fn env(pairs: &[(&str, &str)]) -> impl Fn(&str) -> Option<String> {
        let map: HashMap<String, String> = pairs.iter().map(|(k, v)| (k.to_string(), v.to_string())).collect();
        move |name| map.get(name).cloned()
    }

    #[test]
    fn parts_split_samples_into_contiguous_ranges_that_tile() {
        let settings = RenderSettings {
            samples_per_pixel: Some(10),
            ..Default::default()
        };
        for parts in [1, 2, 3, 7, 10, 13] {
            let mut next = 0;
            for part in 0..parts {
                let share = plan_share(&settings, &PartRequest::Part { part, parts }).expect("splits");
                assert_eq!((share.samples.start, share.rows), (next, RowSet::ALL));
                next = share.samples.end;
            }
            assert_eq!(next, 10, "{parts} parts");
        }
        let adaptive = RenderSettings {
            adaptive_threshold: Some(0.1),
            ..settings
        };
        let share = plan_share(&adaptive, &PartRequest::Part { part: 2, parts: 3 }).expect("splits by rows");
        assert_eq!((share.samples, share.rows), (0..10, RowSet { first: 2, step: 3 }));
    }

    #[test]
    fn part_arguments_parse_from_text_and_schedulers() {
        let none = env(&[]);
        assert_eq!(
            PartRequest::parse_part("2/5", &none).ok(),
            Some(PartRequest::Part { part: 2, parts: 5 })
        );
        let slurm = env(&[
            ("SLURM_ARRAY_TASK_ID", "5"),
            ("SLURM_ARRAY_TASK_MIN", "3"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        assert_eq!(
            PartRequest::parse_part("auto", &slurm).ok(),
            Some(PartRequest::Part { part: 2, parts: 4 })
        );
        let kubernetes = env(&[("JOB_COMPLETION_INDEX", "6")]);
        assert_eq!(
            PartRequest::parse_part("auto/7", &kubernetes).ok(),
            Some(PartRequest::Part { part: 6, parts: 7 })
        );
        let message = |text: &str, env: &dyn Fn(&str) -> Option<String>| {
            PartRequest::parse_part(text, env)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        assert!(message("auto", &kubernetes).contains("--part auto/N"));
        assert!(message("auto", &none).starts_with("--part auto: neither SLURM_ARRAY_TASK_ID"));
        assert!(message("auto/8", &kubernetes).is_empty());
        assert_eq!(
            message("4/4", &none),
            "--part: part 4 of 4 does not exist (parts are 0 to N−1)"
        );
        assert!(message("1-4", &none).starts_with("--part: expected K/N"));
        assert!(message("auto/3", &slurm).contains("4 tasks but --part says 3"));
        let stepped = env(&[
            ("SLURM_ARRAY_TASK_ID", "4"),
            ("SLURM_ARRAY_TASK_STEP", "2"),
            ("SLURM_ARRAY_TASK_COUNT", "4"),
        ]);
        assert!(message("auto", &stepped).contains("steps by 2"));
        assert_eq!(PartRequest::parse_samples(" 8..16").ok(), Some(PartRequest::Samples(8..16)));
        for bad in ["8", "16..8", "3..3", "-1..4", "0..4294967296"] {
            assert!(PartRequest::parse_samples(bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn unsplittable_renders_are_refused_with_the_reason() {
        let refused = |settings: RenderSettings, request: PartRequest| {
            plan_share(&settings, &request)
                .err()
                .map(|e| e.to_string())
                .unwrap_or_default()
        };
        let timed = RenderSettings {
            time_limit: Some(std::time::Duration::from_secs(1)),
            samples_per_pixel: None,
            ..Default::default()
        };
        assert!(refused(timed, PartRequest::Part { part: 0, parts: 2 }).contains("time limit"));
        let sppm = RenderSettings {
            integrator: IntegratorKind::Sppm,
            ..Default::default()
        };
        assert!(refused(sppm.clone(), PartRequest::Samples(0..4)).contains("--radius-schedule global"));
        let mut global = sppm;
        global.sppm.radius_schedule = RadiusSchedule::Global;
        assert_eq!(
            plan_share(&global, &PartRequest::Samples(4..8)).ok().map(|s| s.samples),
            Some(4..8)
        );
        let adaptive = RenderSettings {
            adaptive_threshold: Some(0.05),
            ..Default::default()
        };
        assert!(refused(adaptive.clone(), PartRequest::Samples(4..8)).contains("--part K/N, which splits them by rows"));
        assert!(plan_share(&adaptive, &PartRequest::Samples(0..8)).is_ok());
    }
}
