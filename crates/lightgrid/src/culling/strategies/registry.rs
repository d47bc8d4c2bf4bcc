//! The light-assignment registry: one row per `--assign` strategy (`auto` resolves to one of
//! them, `Assign::resolve`). Adding a strategy is one file implementing
//! [`AssignStrategy`](crate::culling::strategies::AssignStrategy) and one row here; the tests iterate
//! the rows.

use crate::culling::strategies::{AssignStrategy, StrategyContext};
use crate::frame::Assign;

/// One registry row.
pub struct StrategyInfo {
    /// The strategy this row describes.
    pub assign: Assign,
    /// The `--assign` value (and serde's, `Assign`'s attributes: a test checks they agree).
    pub name: &'static str,
    /// One line on how the strategy works (`lightgrid list`, the viewer's hover text).
    pub description: &'static str,
    /// The frame waits for the GPU part-way (the cell bounds read back: the papers' CPU
    /// pipeline); the others record into the frame's one submission.
    #[cfg_attr(not(feature = "testing"), allow(dead_code))]
    pub reads_back: bool,
    /// It assigns on the CPU, from the lights there (a [`crate::LightCuller`] is given them in
    /// `CullInputs::cpu_lights`).
    pub cpu_lights: bool,
    pub(crate) create: fn(&StrategyContext) -> Box<dyn AssignStrategy>,
}

/// The registry: every strategy `--assign` can name (`auto` resolves to one of them).
pub const STRATEGIES: &[StrategyInfo] = &[
    StrategyInfo {
        assign: Assign::Cpu,
        name: "cpu",
        description: "CPU: projected sphere rectangles, per-cell depth test (rayon); grid uploaded",
        cpu_lights: true,
        reads_back: true,
        create: crate::culling::strategies::assign_cpu::create_strategy,
    },
    StrategyInfo {
        assign: Assign::Gather,
        name: "gather",
        description: "GPU: one workgroup per occupied cell tests every light (forward-plus §4)",
        cpu_lights: false,
        reads_back: false,
        create: crate::culling::strategies::gather::create_strategy,
    },
    StrategyInfo {
        assign: Assign::Scatter,
        name: "scatter",
        description: "GPU: one thread per light emits (cell, light) pairs, radix-sorted by cell (forward-plus §4)",
        cpu_lights: false,
        reads_back: false,
        create: crate::culling::strategies::scatter::create_strategy,
    },
    StrategyInfo {
        assign: Assign::Bvh,
        name: "bvh",
        description: "light BVH built on the CPU each frame, walked per occupied cell on the GPU (tiled-forward-shading §4.4)",
        cpu_lights: true,
        reads_back: false,
        create: crate::culling::strategies::bvh::create_strategy,
    },
    StrategyInfo {
        assign: Assign::BvhGpu,
        name: "bvh-gpu",
        description: "the same BVH built on the GPU (Morton codes, radix sort), walked the same way",
        cpu_lights: false,
        reads_back: false,
        create: crate::culling::strategies::bvh_gpu::create_strategy,
    },
    StrategyInfo {
        assign: Assign::ZBin,
        name: "zbin",
        description: "GPU z-binning (Drobot 2017): lights sorted by depth, per-slice index ranges, per-tile light bit masks",
        cpu_lights: false,
        reads_back: false,
        create: crate::culling::strategies::zbin::create_strategy,
    },
];

/// `--assign auto`: not a strategy of its own but a choice among the rows
/// ([`Assign::resolve`]).
const AUTO_NAME: &str = "auto";
const AUTO_DESCRIPTION: &str =
    "software adapter: cpu; hardware GPU: gather up to 8192 lights, bvh-gpu above";

/// Every `--assign` value as the settings table lists them: `auto` (the default), then the
/// registry's rows, built from the registry at compile time.
pub(crate) const ASSIGN_VALUES: [Assign; STRATEGIES.len() + 1] = {
    let mut out = [Assign::Auto; STRATEGIES.len() + 1];
    let mut i = 0;
    while i < STRATEGIES.len() {
        out[i + 1] = STRATEGIES[i].assign;
        i += 1;
    }
    out
};

/// The registry row of a (resolved) strategy.
pub(crate) fn find_strategy(assign: Assign) -> Option<&'static StrategyInfo> {
    STRATEGIES.iter().find(|s| s.assign == assign)
}

/// The strategy ids' names and descriptions come from the registry: `Assign` is only the
/// typed id of a row (or `Auto`).
impl Assign {
    /// Every `--assign` value: the registry's rows, then `auto`.
    pub fn all() -> impl Iterator<Item = Assign> {
        STRATEGIES.iter().map(|s| s.assign).chain([Assign::Auto])
    }

    /// The strategy's `--assign` value (also its serde name); `auto` for [`Assign::Auto`].
    pub fn name(self) -> &'static str {
        find_strategy(self).map_or(AUTO_NAME, |s| s.name)
    }

    /// One line on how the strategy works (`lightgrid list`).
    pub fn description(self) -> &'static str {
        find_strategy(self).map_or(AUTO_DESCRIPTION, |s| s.description)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The registry is the list of strategies: every `Assign` value but `auto` has exactly
    /// one row (a variant without one would be named "auto" and refused at its first frame),
    /// and each row's name is the one serde reads and writes.
    #[test]
    fn every_strategy_value_has_one_row_and_its_serde_name() {
        let variants = [
            Assign::Cpu,
            Assign::Gather,
            Assign::Scatter,
            Assign::Bvh,
            Assign::BvhGpu,
            Assign::ZBin,
            Assign::Auto,
        ];
        // A match without a wildcard: a new variant must be added to `variants` above.
        for a in variants {
            match a {
                Assign::Cpu
                | Assign::Gather
                | Assign::Scatter
                | Assign::Bvh
                | Assign::BvhGpu
                | Assign::ZBin => {
                    assert_eq!(STRATEGIES.iter().filter(|s| s.assign == a).count(), 1);
                }
                Assign::Auto => assert!(find_strategy(a).is_none()),
            }
            let json = serde_json::to_string(&a).unwrap();
            assert_eq!(json, format!("\"{}\"", a.name()));
        }
        assert_eq!(Assign::all().collect::<Vec<_>>(), variants);
    }
}
