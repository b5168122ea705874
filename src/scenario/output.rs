//! The types of `[output]`: the frame formats, and whether a split run gathers its frames.

use anyhow::{Result, bail};

/// The frame formats of `[output] formats`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Formats {
    /// `particlesNNNNNN.csv`, the original program's format.
    pub csv: bool,
    /// `particlesNNNNNN.vtu`, `mesh.vtu` and `particles.pvd` for ParaView.
    pub vtk: bool,
}

impl Formats {
    pub(super) fn parse(names: Option<Vec<String>>) -> Result<Formats> {
        let Some(names) = names else {
            return Ok(Formats {
                csv: true,
                vtk: false,
            });
        };
        let mut f = Formats {
            csv: false,
            vtk: false,
        };
        for name in &names {
            match name.as_str() {
                "csv" => f.csv = true,
                "vtk" => f.vtk = true,
                other => bail!(
                    "[output] formats: unknown format \"{other}\": the formats are \"csv\" and \"vtk\""
                ),
            }
        }
        if !f.csv && !f.vtk {
            bail!("[output] formats must name at least one of \"csv\" and \"vtk\"");
        }
        Ok(f)
    }
}

/// `[output] gather`: whether a run split over processes gathers each frame (and contact
/// network) into one file, written by the first process, or each process writes its own
/// piece (`particlesNNNNNN_K.vtu` listed by `particlesNNNNNN.pvtu`; CSV pieces with ids).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Gather {
    /// Gathered below [`Gather::AUTO_LIMIT`] particles, in pieces from there on.
    #[default]
    Auto,
    Always,
    Never,
}

impl Gather {
    /// The number of particles from which `auto` writes pieces: 10^7 particles, 1.2 GB of
    /// state, is about what one process should gather.
    pub const AUTO_LIMIT: u64 = 10_000_000;

    pub(super) fn parse(name: Option<String>) -> Result<Gather> {
        Ok(match name.as_deref() {
            None | Some("auto") => Gather::Auto,
            Some("always") => Gather::Always,
            Some("never") => Gather::Never,
            Some(other) => bail!(
                "[output] gather: unknown value \"{other}\": it is \"auto\" (gathered below \
                 10^7 particles), \"always\" or \"never\""
            ),
        })
    }

    /// The name in a scenario file.
    pub fn name(self) -> &'static str {
        match self {
            Gather::Auto => "auto",
            Gather::Always => "always",
            Gather::Never => "never",
        }
    }
}
