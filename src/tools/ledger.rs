//! The energy ledger of a run as `tinydem analyze --energy` tells it: from `log.csv`'s
//! columns (`[output] energy_ledger`), where the energy put in went.

use anyhow::{Result, bail};

use crate::model::ledger::COLUMNS;
use crate::tools::plot::Table;

/// The columns `analyze --energy` plots against time: the kinetic energy and the ledger's
/// work, stored and dissipated energy (not the energy spawned and removed, nor the
/// residual, at the rounding, which the breakdown gives), those not zero throughout `log`.
pub fn plotted(log: &Table) -> Vec<&'static str> {
    let ledger = COLUMNS.into_iter().filter(|c| !c.starts_with("energy_"));
    std::iter::once("kinetic_energy")
        .chain(ledger)
        .filter(|c| log.column(c).is_ok_and(|v| v.iter().any(|&x| x != 0.0)))
        .collect()
}

/// One line of the breakdown: a column, its value at the last frame \[J\] and its share of
/// the energy put in (the kinetic and stored energy at the start, the work of gravity and
/// the walls, the energy spawned).
#[derive(Clone, Debug, PartialEq)]
pub struct Share {
    pub column: &'static str,
    pub value: f64,
    pub share: f64,
}

/// Where the energy of the run in `log` (its `log.csv`) went by its last frame: what holds
/// it (the grains' motion, the contacts) and what took it (each mode's dissipation, the
/// drag, the outlets), each with its share of what was put in; the residual last.
pub fn breakdown(log: &Table) -> Result<Vec<Share>> {
    if !log.header.iter().any(|h| h == "energy_residual") {
        bail!("log.csv has no energy ledger: run with [output] energy_ledger = true");
    }
    let last = |c: &str| -> Result<f64> {
        let v = log.column(c)?;
        Ok(*v.last().unwrap_or(&0.0))
    };
    let first = |c: &str| -> Result<f64> { Ok(*log.column(c)?.first().unwrap_or(&0.0)) };
    let put_in = first("kinetic_energy")?
        + first("stored_elastic")?
        + last("work_gravity")?
        + last("work_walls")?
        + last("energy_spawned")?;
    let held = ["kinetic_energy", "stored_elastic"];
    let taken = COLUMNS
        .iter()
        .filter(|c| c.starts_with("dissipated_") || **c == "energy_removed");
    let mut out = Vec::new();
    for &column in held.iter().chain(taken).chain(&["energy_residual"]) {
        let value = last(column)?;
        out.push(Share {
            column,
            value,
            share: if put_in != 0.0 { value / put_in } else { 0.0 },
        });
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_breakdown_shares_what_was_put_in() {
        let mut csv = String::from("time,kinetic_energy");
        for c in COLUMNS {
            csv += &format!(",{c}");
        }
        csv += "\n0,1,0,0,0,0,0,0,0,0,0,0,0,0\n";
        // 1 J at the start, gravity 3 J: 1 J moving, 2 J lost in the normal mode, 1 J in
        // sliding.
        csv += "1,1,3,0,0,2,1,0,0,0,0,0,0,0\n";
        let table = Table::parse(&csv, "log.csv").unwrap();
        let b = breakdown(&table).unwrap();
        let of = |c: &str| b.iter().find(|s| s.column == c).unwrap().share;
        assert_eq!(
            (
                of("kinetic_energy"),
                of("dissipated_normal"),
                of("dissipated_sliding")
            ),
            (0.25, 0.5, 0.25)
        );
        assert_eq!(b.last().unwrap().column, "energy_residual");
        let none = Table::parse("time,kinetic_energy\n0,1\n", "log.csv").unwrap();
        assert!(format!("{:#}", breakdown(&none).unwrap_err()).contains("energy_ledger"));
    }
}
