//! The rules a BSP must follow: the format's structure (every index and offset in range, no NaN)
//! and what real engines enforce when they load or play it (QuakeSpasm and its descendants,
//! DarkPlaces, FTE, and the vanilla engines), each a named [`Rule`] with the engine's message.
//! `quake-formats/README.md` holds the table of rules; `slipgate info` prints the problems.

mod bspx;
mod counts;
mod entities;
mod gate;
mod node_portals;
mod rules;
mod structure;
mod surfaces;
mod textures;
mod trees;

pub use gate::{MAX_TREE_DEPTH, TreeUse, check_usable, check_usable_for};
pub use node_portals::{DARKPLACES_PORTAL_EPSILON, darkplaces_divide};
pub use rules::{Rule, RuleInfo};

use super::Bsp;

/// How bad a problem is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Severity {
    /// A mainstream engine (QuakeSpasm family, DarkPlaces or FTE) refuses the file, reads out of
    /// bounds or crashes loading or playing it.
    Error,
    /// Only vanilla or limited engines refuse it, or play goes wrong (named in the detail).
    Warning,
}

impl std::fmt::Display for Severity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
        })
    }
}

/// One thing wrong with a BSP: the rule it breaks and the lump and record where.
#[derive(Debug, Clone, PartialEq)]
pub struct Problem {
    /// The rule broken.
    pub rule: Rule,
    /// The rule's severity, kept here for callers that only filter.
    pub severity: Severity,
    /// Name of the lump the problem is in, as in [`LUMP_NAMES`](super::LUMP_NAMES) (`"faces"`).
    pub lump: &'static str,
    /// The record's index in its lump (0 for whole-lump problems).
    pub index: usize,
    /// What is wrong with this record, with the values involved.
    pub detail: String,
}

impl std::fmt::Display for Problem {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let info = self.rule.info();
        write!(
            f,
            "{}: {}[{}]: {} [{}; {}: {}]",
            self.severity, self.lump, self.index, self.detail, info.id, info.engines, info.message
        )
    }
}

/// Collects problems while the rule families look at one BSP.
struct Checker<'a> {
    bsp: &'a Bsp,
    problems: Vec<Problem>,
}

impl Checker<'_> {
    fn report(&mut self, rule: Rule, lump: &'static str, index: usize, detail: String) {
        self.problems.push(Problem {
            rule,
            severity: rule.severity(),
            lump,
            index,
            detail,
        });
    }
}

/// Every problem found; with no [`Severity::Error`] the engines named in the rules load and play
/// the file.
pub fn validate(bsp: &Bsp) -> Vec<Problem> {
    check_families(
        bsp,
        &[
            structure::check,
            trees::check,
            node_portals::check,
            surfaces::check,
            bspx::check,
            textures::check,
            counts::check,
            entities::check,
        ],
    )
}

/// The rule families that hold every rule tools refuse ([`Rule::refused_by_tools`]): what the
/// stage gate runs. The others (DarkPlaces' node portals, textures, entities) only concern
/// engines, and the node-portal replay alone was 12-15% of a default light run.
fn validate_for_tools(bsp: &Bsp) -> Vec<Problem> {
    check_families(
        bsp,
        &[
            structure::check,
            trees::check,
            surfaces::check,
            counts::check,
        ],
    )
}

/// The problems `families` find, in their order.
fn check_families(bsp: &Bsp, families: &[fn(&mut Checker)]) -> Vec<Problem> {
    let mut c = Checker {
        bsp,
        problems: Vec::new(),
    };
    for check in families {
        check(&mut c);
    }
    c.problems
}
