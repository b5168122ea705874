//! `tinydem verify`: the analytic cases run with this build, a table of their checks, and
//! a report; fails if any check does.

use std::path::PathBuf;

use anyhow::{Context, Result, bail};
use clap::Args;

use tinydem::tools::verify;

#[derive(Args)]
pub struct VerifyArgs {
    /// Only the quick cases (under a minute).
    #[arg(long)]
    quick: bool,
    /// Only these cases (by name; comma-separated).
    #[arg(long, value_delimiter = ',')]
    only: Vec<String>,
    /// Write the report (verify.md: what each case is, and the table) into this directory.
    #[arg(long)]
    report: Option<PathBuf>,
}

impl VerifyArgs {
    pub fn execute(self) -> Result<()> {
        let checks = verify::run(&self.only, self.quick)?;
        print!("{}", verify::table(&checks));
        if let Some(dir) = &self.report {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create report directory {}", dir.display()))?;
            let path = dir.join("verify.md");
            std::fs::write(&path, verify::report(&checks))
                .with_context(|| format!("cannot write {}", path.display()))?;
        }
        let failed = checks.iter().filter(|c| !c.passes()).count();
        if failed > 0 {
            bail!("{failed} of {} checks failed", checks.len());
        }
        println!("all {} checks pass", checks.len());
        Ok(())
    }
}
