//! Work split over many processes or machines (issue 46): shards of a sequence's frames, of a
//! reference's samples and of a lab's points, and the merge that joins them. Each shard is a
//! deterministic slice of the one-process run, so a scheduler (Slurm's job arrays:
//! `scripts/slurm/`) can run them anywhere, re-run a failed one, and merge what they wrote.
//!
//! - [`Shard`]: "part `i` of `n`", given as `--shard i/n` or read from a Slurm array task's
//!   environment ([`Shard::from_slurm_env`]).
//! - [`frames`]: a sequence's frame range and the history warm-up before it.
//! - [`partial`]: a reference's partial sums, keyed by the global sample index.
//! - [`manifest`]: what a sequence shard wrote, so a merge can tell a missing frame.
//! - [`merge`]: `shine merge`, refusing a missing or duplicated part by name.
//! - [`identity`]: the keys a run's scene is known by across machines.

pub mod frames;
pub mod identity;
pub mod manifest;
pub mod merge;
pub mod partial;

use std::fmt;
use std::ops::Range;
use std::str::FromStr;

/// Largest number of shards one run may be split into.
pub const MAX_SHARDS: u32 = 1 << 16;

/// Slurm's variables of a job array task ([`Shard::from_slurm_env`]): its index, the array's
/// task count, and the smallest index (arrays may start above 0: `--array=1-4`).
pub const SLURM_TASK_ID: &str = "SLURM_ARRAY_TASK_ID";
/// The number of tasks of the job array.
pub const SLURM_TASK_COUNT: &str = "SLURM_ARRAY_TASK_COUNT";
/// The smallest task index of the job array.
pub const SLURM_TASK_MIN: &str = "SLURM_ARRAY_TASK_MIN";
/// The largest task index of the job array.
pub const SLURM_TASK_MAX: &str = "SLURM_ARRAY_TASK_MAX";

/// Part `index` of `count` equal, contiguous parts of a run (0-based: `0/4` … `3/4`). Read
/// from a file, it is checked as [`Shard::new`] checks it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, serde::Deserialize)]
#[serde(try_from = "UncheckedShard")]
pub struct Shard {
    /// Which part, `0..count`.
    pub index: u32,
    /// How many parts.
    pub count: u32,
}

/// A shard as a file states it, before [`Shard::new`]'s checks.
#[derive(serde::Deserialize)]
struct UncheckedShard {
    index: u32,
    count: u32,
}

impl TryFrom<UncheckedShard> for Shard {
    type Error = ShardError;

    fn try_from(s: UncheckedShard) -> Result<Self, Self::Error> {
        Shard::new(s.index, s.count)
    }
}

/// Why a shard was refused.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ShardError {
    /// Not of the form `i/n` with `0 ≤ i < n ≤ MAX_SHARDS`.
    #[error("shard `{0}`: {1}")]
    Malformed(String, String),
    /// A Slurm variable that is not a number, or an index outside the array.
    #[error("{0}")]
    Environment(String),
}

impl Shard {
    /// The whole run as one part.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Part `index` of `count`, checked.
    pub fn new(index: u32, count: u32) -> Result<Self, ShardError> {
        let text = format!("{index}/{count}");
        if count == 0 || count > MAX_SHARDS {
            return Err(ShardError::Malformed(
                text,
                format!("the count must be 1..={MAX_SHARDS}"),
            ));
        }
        if index >= count {
            return Err(ShardError::Malformed(
                text,
                format!("the index counts from 0 and must be below {count}"),
            ));
        }
        Ok(Self { index, count })
    }

    /// The shard of this Slurm array task, when the process runs as one
    /// ([`SLURM_TASK_ID`] set): index − [`SLURM_TASK_MIN`] of [`SLURM_TASK_COUNT`].
    pub fn from_slurm_env() -> Result<Option<Self>, ShardError> {
        Self::from_vars(|key| std::env::var(key).ok())
    }

    /// [`Shard::from_slurm_env`] over any variable lookup (tests).
    pub fn from_vars(var: impl Fn(&str) -> Option<String>) -> Result<Option<Self>, ShardError> {
        let Some(id) = var(SLURM_TASK_ID) else {
            return Ok(None);
        };
        let number = |key: &str, text: &str| {
            text.trim().parse::<u32>().map_err(|_| {
                ShardError::Environment(format!("{key}={text:?} is not a task number"))
            })
        };
        let id = number(SLURM_TASK_ID, &id)?;
        let count = var(SLURM_TASK_COUNT).ok_or_else(|| {
            ShardError::Environment(format!(
                "{SLURM_TASK_ID} is set but {SLURM_TASK_COUNT} is not: give --shard i/n"
            ))
        })?;
        let count = number(SLURM_TASK_COUNT, &count)?;
        let min = match var(SLURM_TASK_MIN) {
            Some(min) => number(SLURM_TASK_MIN, &min)?,
            None => 0,
        };
        // Arrays with steps or gaps (`--array=0-7:2`, `--array=1,5`) do not number their tasks
        // min..min + count: every task refuses, rather than some running and parts missing.
        let max = match var(SLURM_TASK_MAX) {
            Some(max) => number(SLURM_TASK_MAX, &max)?,
            None => min.saturating_add(count).saturating_sub(1),
        };
        let contiguous = max.checked_sub(min).map(|span| span + 1) == Some(count);
        let index = id
            .checked_sub(min)
            .filter(|i| *i < count && contiguous)
            .ok_or_else(|| {
                ShardError::Environment(format!(
                    "array task {id} is not one of {count} tasks numbered {min}..={max} in a \
                     contiguous array: use --array=A-B, or give --shard i/n"
                ))
            })?;
        Self::new(index, count).map(Some)
    }

    /// This part's share of `0..total`: contiguous, the parts' sizes differing by at most one,
    /// together covering `0..total` once.
    pub fn range(&self, total: u32) -> Range<u32> {
        let at = |k: u32| (u64::from(total) * u64::from(k) / u64::from(self.count)) as u32;
        at(self.index)..at(self.index + 1)
    }

    /// Whether this is the whole run.
    pub fn is_whole(&self) -> bool {
        self.count == 1
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl FromStr for Shard {
    type Err = ShardError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        let malformed = |why: &str| ShardError::Malformed(s.to_owned(), why.to_owned());
        let (i, n) = s
            .split_once('/')
            .ok_or_else(|| malformed("write it as i/n, part i (from 0) of n, e.g. 2/4"))?;
        let number = |t: &str| {
            t.trim()
                .parse::<u32>()
                .map_err(|_| malformed("i and n must be whole numbers, e.g. 2/4"))
        };
        Self::new(number(i)?, number(n)?)
    }
}

/// The shard a command runs as: `given` (`--shard`), else the Slurm array task's, else the
/// whole run. The second value says where it came from, for the command's report.
pub fn resolve(given: Option<Shard>) -> Result<(Shard, &'static str), ShardError> {
    if let Some(shard) = given {
        return Ok((shard, "--shard"));
    }
    Ok(match Shard::from_slurm_env()? {
        Some(shard) => (shard, "the Slurm array task"),
        None => (Shard::WHOLE, "one process"),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_refuse_by_name() {
        assert_eq!("2/4".parse::<Shard>(), Ok(Shard { index: 2, count: 4 }));
        for bad in ["4/4", "1/0", "a/4", "3", "-1/4", "1/70000"] {
            let err = bad.parse::<Shard>().unwrap_err().to_string();
            assert!(err.contains(bad), "{bad}: {err}");
        }
    }

    #[test]
    fn shards_read_from_files_are_checked() {
        let read = |text: &str| serde_json::from_str::<Shard>(text);
        assert_eq!(
            read(r#"{"index":1,"count":2}"#).unwrap(),
            Shard { index: 1, count: 2 }
        );
        assert!(read(r#"{"index":5,"count":2}"#).is_err());
        assert!(read(r#"{"index":0,"count":4000000000}"#).is_err());
    }

    #[test]
    fn ranges_tile_the_whole_once() {
        for total in [0, 1, 7, 16, 600] {
            for count in [1, 3, 4, 7] {
                let mut next = 0;
                for index in 0..count {
                    let r = Shard::new(index, count).unwrap().range(total);
                    assert_eq!(r.start, next, "{total} over {count}");
                    assert!(r.len() as u32 <= total / count + 1);
                    next = r.end;
                }
                assert_eq!(next, total);
            }
        }
    }

    #[test]
    fn slurm_variables_give_the_shard() {
        let env = |vars: &'static [(&'static str, &'static str)]| {
            move |key: &str| {
                vars.iter()
                    .find(|(k, _)| *k == key)
                    .map(|(_, v)| v.to_string())
            }
        };
        assert_eq!(Shard::from_vars(env(&[])), Ok(None));
        const FOUR: &[(&str, &str)] = &[(SLURM_TASK_ID, "3"), (SLURM_TASK_COUNT, "4")];
        assert_eq!(
            Shard::from_vars(env(FOUR)),
            Ok(Some(Shard { index: 3, count: 4 }))
        );
        const FROM_ONE: &[(&str, &str)] = &[
            (SLURM_TASK_ID, "1"),
            (SLURM_TASK_COUNT, "4"),
            (SLURM_TASK_MIN, "1"),
        ];
        assert_eq!(
            Shard::from_vars(env(FROM_ONE)),
            Ok(Some(Shard { index: 0, count: 4 }))
        );
        const OUTSIDE: &[(&str, &str)] = &[(SLURM_TASK_ID, "5"), (SLURM_TASK_COUNT, "4")];
        const NOT_A_NUMBER: &[(&str, &str)] = &[(SLURM_TASK_ID, "x"), (SLURM_TASK_COUNT, "4")];
        const NO_COUNT: &[(&str, &str)] = &[(SLURM_TASK_ID, "1")];
        const STEPPED: &[(&str, &str)] = &[
            (SLURM_TASK_ID, "2"),
            (SLURM_TASK_COUNT, "4"),
            (SLURM_TASK_MIN, "0"),
            (SLURM_TASK_MAX, "6"),
        ];
        for bad in [OUTSIDE, NOT_A_NUMBER, NO_COUNT, STEPPED] {
            let got = Shard::from_vars(env(bad));
            assert!(matches!(got, Err(ShardError::Environment(_))), "{bad:?}");
        }
    }
}
