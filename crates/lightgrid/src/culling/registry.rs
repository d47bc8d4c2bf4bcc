//! The light-assignment registry: one row per `--assign` strategy (`auto` resolves to one of
//! them, `Assign::resolve`). Adding a strategy is one file implementing
//! [`AssignStrategy`](super::strategy::AssignStrategy) and one row here; the tests iterate
//! the rows.

use super::strategy::{AssignStrategy, StrategyContext};
use crate::frame::Assign;

/// One registry row.
pub struct StrategyInfo {
    pub assign: Assign,
    /// The frame waits for the GPU part-way (the cell bounds read back: the papers' CPU
    /// pipeline); the others record into the frame's one submission.
    pub reads_back: bool,
    pub create: fn(&StrategyContext) -> Box<dyn AssignStrategy>,
}

/// The registry: every strategy `--assign` can name (`auto` resolves to one of them).
pub const STRATEGIES: &[StrategyInfo] = &[
    StrategyInfo {
        assign: Assign::Cpu,
        reads_back: true,
        create: super::assign_cpu::create_strategy,
    },
    StrategyInfo {
        assign: Assign::Gather,
        reads_back: false,
        create: super::gather::create_strategy,
    },
    StrategyInfo {
        assign: Assign::Scatter,
        reads_back: false,
        create: super::scatter::create_strategy,
    },
    StrategyInfo {
        assign: Assign::Bvh,
        reads_back: false,
        create: super::bvh::create_strategy,
    },
    StrategyInfo {
        assign: Assign::BvhGpu,
        reads_back: false,
        create: super::bvh_gpu::create_strategy,
    },
];

/// The registry row of a (resolved) strategy.
pub fn find_strategy(assign: Assign) -> Option<&'static StrategyInfo> {
    STRATEGIES.iter().find(|s| s.assign == assign)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The registry is the list of strategies: every `--assign` value but `auto` has exactly
    /// one row (a variant without one would be refused at its first frame, and left out of
    /// every test that iterates the registry).
    #[test]
    fn every_strategy_value_has_one_row() {
        for a in Assign::ALL {
            let rows = STRATEGIES.iter().filter(|s| s.assign == a).count();
            let expected = usize::from(a != Assign::Auto);
            assert_eq!(rows, expected, "{}", a.name());
        }
        assert_eq!(STRATEGIES.len(), Assign::ALL.len() - 1);
    }
}
