//! The committed budgets of octrace's deterministic figures (`budgets.toml`
//! at the repository's root): qemu's instruction counts, the emulated
//! Pico's cycles, flash and RAM. The tests that measure a figure anyway
//! (`tests/tests/firmware.rs`, `tests/tests/pico.rs`) check it here, so
//! nothing is built or run twice for it.
//!
//! Invariants: a figure more than [`TOLERANCE_PERCENT`] worse (larger) than
//! its budget fails its test, as does a figure with no budget and a budget
//! no run measured; a figure that beats its budget by more than that is
//! reported with the line that moves the budget, and passes. Every figure
//! is smaller-is-better.

use crate::repo;
use std::collections::BTreeSet;
use std::path::PathBuf;

/// How much worse than its budget a figure may be before its test fails.
pub const TOLERANCE_PERCENT: u64 = 1;

/// The budgets file.
pub fn path() -> PathBuf {
    repo().join("budgets.toml")
}

/// One section of `budgets.toml` (a suite: `firmware`, `pico`) and what
/// its checks found.
pub struct Budgets {
    section: String,
    table: toml::Table,
    checked: BTreeSet<(String, String)>,
    /// Every figure checked against a budget, as the run printed it.
    measured: Vec<String>,
    failures: Vec<String>,
    improved: Vec<String>,
}

impl Budgets {
    /// The budgets of `section`.
    pub fn load(section: &str) -> Result<Budgets, String> {
        let path = path();
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        let all: toml::Table = text.parse().map_err(|e| format!("{}: {e}", path.display()))?;
        let table = match all.get(section) {
            Some(toml::Value::Table(table)) => table.clone(),
            _ => return Err(format!("{}: no [{section}] table", path.display())),
        };
        Ok(Budgets {
            section: section.to_owned(),
            table,
            checked: BTreeSet::new(),
            measured: Vec::new(),
            failures: Vec::new(),
            improved: Vec::new(),
        })
    }

    /// Checks `figure` (say `instructions`) of `subject` (say `microbit
    /// fig5_1 160x128 rgb888`) against its budget: `value` may be at most
    /// [`TOLERANCE_PERCENT`] above it.
    pub fn check(&mut self, subject: &str, figure: &str, value: u64) {
        self.checked.insert((subject.to_owned(), figure.to_owned()));
        let line = |budget: u64| format!("[{}.\"{subject}\"] {figure} = {{ budget = {}, ... }}", self.section, budget);
        let Some(budget) = self.budget(subject, figure) else {
            self.failures.push(format!(
                "{subject}: {figure} is {value} and has no budget: add {} with a one-line `why`",
                line(value)
            ));
            return;
        };
        let budget = match budget {
            Ok(budget) => budget,
            Err(e) => return self.failures.push(e),
        };
        let percent = |v: u64| 100.0 * (v as f64 / budget as f64 - 1.0);
        self.measured.push(format!("{subject}: {figure} {value} ({:+.2} % against {budget})", percent(value)));
        if value * 100 > budget * (100 + TOLERANCE_PERCENT) {
            self.failures.push(format!(
                "{subject}: {figure} is {value}, {:+.2} % against its budget {budget} (more than {TOLERANCE_PERCENT} % \
                 worse). If the change is worth it, raise the budget and say why: {}",
                percent(value),
                line(value)
            ));
        } else if value * 100 < budget * (100 - TOLERANCE_PERCENT) {
            self.improved.push(format!(
                "{subject}: {figure} is {value}, {:+.2} %: move its budget: {}",
                percent(value),
                line(value)
            ));
        }
    }

    /// The budget of `figure` of `subject`: None when it has none.
    fn budget(&self, subject: &str, figure: &str) -> Option<Result<u64, String>> {
        let entry = self.table.get(subject)?.as_table()?.get(figure)?;
        let budget = entry.as_table().and_then(|t| t.get("budget")).and_then(toml::Value::as_integer);
        let why = entry.as_table().and_then(|t| t.get("why")).and_then(toml::Value::as_str);
        Some(match (budget, why) {
            (Some(budget), Some(why)) if budget > 0 && !why.trim().is_empty() => Ok(budget as u64),
            _ => Err(format!(
                "{}: [{}.\"{subject}\"] {figure} is not {{ budget = a positive integer, why = \"a reason\" }}",
                path().display(),
                self.section
            )),
        })
    }

    /// The figures that beat their budgets, with the line that moves each.
    pub fn improved(&self) -> &[String] {
        &self.improved
    }

    /// Every failed check, and every budget of `subjects` no run checked
    /// (a figure renamed or gone); empty when all are within budget. Budgets
    /// of other subjects (a run skipped, another test's) are left alone.
    pub fn failures(&self, subjects: &[String]) -> Vec<String> {
        let mut failures = self.failures.clone();
        for subject in subjects {
            let figures = self.table.get(subject).and_then(toml::Value::as_table);
            for figure in figures.into_iter().flat_map(|t| t.keys()) {
                if !self.checked.contains(&(subject.clone(), figure.clone())) {
                    failures.push(format!(
                        "[{}.\"{subject}\"] {figure}: a budget no run measured (remove it, or measure it)",
                        self.section
                    ));
                }
            }
        }
        failures
    }

    /// Prints every figure against its budget and the improvements, then
    /// panics with every failure, if any.
    pub fn assert_within(&self, subjects: &[String]) {
        for line in &self.measured {
            println!("measured: {line}");
        }
        for line in &self.improved {
            println!("budget: {line}");
        }
        let failures = self.failures(subjects);
        assert!(
            failures.is_empty(),
            "{} figure(s) against budgets.toml (it says how to move a budget):\n{}",
            failures.len(),
            failures.join("\n")
        );
        println!("budgets: {} figures of [{}] within {TOLERANCE_PERCENT} %", self.checked.len(), self.section);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn budgets(text: &str) -> Budgets {
        let table: toml::Table = text.parse().unwrap();
        Budgets {
            section: "s".into(),
            table: table["s"].as_table().unwrap().clone(),
            checked: BTreeSet::new(),
            measured: Vec::new(),
            failures: Vec::new(),
            improved: Vec::new(),
        }
    }

    #[test]
    fn worse_by_more_than_one_percent_fails_and_better_says_how_to_move() {
        let text = r#"[s."a"]
x = { budget = 1000, why = "w" }"#;
        let subjects = ["a".to_owned()];
        for (value, fails, improves) in
            [(1010, false, false), (1011, true, false), (990, false, false), (989, false, true)]
        {
            let mut b = budgets(text);
            b.check("a", "x", value);
            assert_eq!(!b.failures(&subjects).is_empty(), fails, "{value}");
            assert_eq!(!b.improved().is_empty(), improves, "{value}");
        }
    }

    #[test]
    fn a_figure_without_budget_a_budget_without_figure_and_a_budget_without_reason_fail() {
        let mut b = budgets(
            r#"[s."a"]
x = { budget = 1000, why = "w" }
y = { budget = 5, why = "w" }
z = { budget = 5, why = "" }"#,
        );
        b.check("a", "x", 1000);
        b.check("a", "new", 7);
        b.check("a", "z", 5);
        let failures = b.failures(&["a".to_owned()]);
        assert_eq!(failures.len(), 3, "{failures:?}");
        assert!(failures[0].contains("no budget") && failures[0].contains("new = { budget = 7"));
        assert!(failures[1].contains("why"));
        assert!(failures[2].contains("y: a budget no run measured"));
    }
}
