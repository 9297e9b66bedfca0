//! The order of the full flow, fixed by the portal graph alone, so that any thread count, any
//! number of shards and a resumed run all give the same sets.
//!
//! Portals run in waves, smallest mightsee first; a flow is bounded by finished flows of earlier
//! waves (tighter than mightsee, which is what makes later flows fast). The costliest portals,
//! those holding [`FINAL_COST`] of the estimated work, are cut into [`FINAL_GROUPS`] groups of
//! neighbouring portals; a final flow is bounded only by shared flows and by those of its own
//! group, so groups can run on different machines. Every shard runs the shared flows itself and
//! its groups; a whole run runs them all, and the bounds, hence the sets, are the same. Maps too
//! small to be worth sharding ([`GROUPED_MIN_WORK`]) get one final group.

use crate::bitset::BitSet;

/// Portal flows of the shared waves run in this many waves (fewer when there are few portals).
const FLOW_WAVES: usize = 200;
const MIN_WAVE_PORTALS: usize = 16;

/// The share of the estimated flow work ([`estimated_cost`]) in the final groups. More makes
/// shards finish sooner and a whole run slower (README, "Shards").
const FINAL_COST: f64 = 0.8;
/// How many final groups: the most shards that share the work.
const FINAL_GROUPS: usize = 16;
/// Maps whose estimated flow work ([`estimated_cost`] summed over portals) is below this get one
/// final group: every flow is bounded by all earlier waves, the fastest plan for one machine,
/// and a sharded run gives all the final work to its first shard. Grouping costs a whole run
/// 1.6-1.8 times the work, so only maps big enough to be worth sharding pay it. Measured
/// estimates: LibreQuake e3m4 7.2e8, e2m4 3.7e9, id e1m1 4.9e9, retrojam1 9.9e9 (9 CPU seconds),
/// `maps/open` 1.3e10 (38 CPU seconds with one group).
pub const GROUPED_MIN_WORK: f64 = 1.1e10;

/// Whether the plan cuts the final portals into groups for shards.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Grouping {
    /// Groups only for maps of at least [`GROUPED_MIN_WORK`] estimated work.
    #[default]
    Auto,
    /// Groups whatever the map's size (tests use it to shard small maps).
    Always,
}

/// A flow's estimated work from its mightsee count: the walk meets each portal it might see on
/// paths whose number grows with the count too.
pub fn estimated_cost(mightsee_count: usize) -> f64 {
    let n = mightsee_count as f64 + 1.0;
    n * n
}

/// Shard `index` (0-based) of `count`: what `--shard K/N` names as `index + 1`/`count`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// Which shard, 0-based (below `count`).
    pub index: usize,
    /// How many shards share the work.
    pub count: usize,
}

impl Shard {
    /// The whole job as one shard.
    pub const WHOLE: Shard = Shard { index: 0, count: 1 };

    /// Parse `K/N` with `1 <= K <= N`.
    pub fn parse(text: &str) -> Result<Shard, String> {
        let bad = || format!("shard `{text}` is not K/N with 1 <= K <= N (for example 2/4)");
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let k: usize = k.trim().parse().map_err(|_| bad())?;
        let n: usize = n.trim().parse().map_err(|_| bad())?;
        if k == 0 || k > n {
            return Err(bad());
        }
        Ok(Shard {
            index: k - 1,
            count: n,
        })
    }
}

impl std::fmt::Display for Shard {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{}/{}", self.index + 1, self.count)
    }
}

/// The waves of one flow run, and which finished flows each flow may use as bounds.
#[derive(Debug, Clone)]
pub struct FlowPlan {
    /// Portals in run order, smallest mightsee first, cut into waves of `wave_len`.
    order: Vec<usize>,
    wave_len: usize,
    /// By portal: its wave.
    wave_of: Vec<u32>,
    /// By portal: 0 for the shared portals, else its final group (1..).
    group_of: Vec<u32>,
    /// Estimated cost of each final group (index 0 for group 1).
    group_cost: Vec<f64>,
    /// By wave: the groups of the portals in later waves, bit `g` for group `g`.
    later_groups: Vec<u64>,
}

impl FlowPlan {
    /// The plan for portals with these mightsee sets, grouped for shards as `grouping` says.
    pub fn new(mightsee: &[BitSet], grouping: Grouping) -> FlowPlan {
        let n = mightsee.len();
        let counts: Vec<usize> = mightsee.iter().map(BitSet::count).collect();
        let cost = |p: usize| estimated_cost(counts[p]);
        let mut order: Vec<usize> = (0..n).collect();
        order.sort_by_key(|&p| (counts[p], p));
        let total: f64 = (0..n).map(cost).sum();
        let groups = if grouping == Grouping::Always || total >= GROUPED_MIN_WORK {
            FINAL_GROUPS
        } else {
            1
        };
        // Walk back from the costliest until the final portals hold their share of the work.
        let mut final_start = n;
        let mut final_cost = 0.0;
        while final_start > 0 && final_cost < FINAL_COST * total {
            final_start -= 1;
            final_cost += cost(order[final_start]);
        }
        // Final groups are runs of portal numbers (portals are numbered in tree order, so a
        // run is a region of the map, and the two ways through a portal stay together) of
        // about equal cost.
        let mut finals = order[final_start..].to_vec();
        finals.sort_unstable();
        let mut group_of = vec![0u32; n];
        let mut group_cost = vec![0.0; groups];
        let mut before = 0.0;
        for p in finals {
            let g = ((before / final_cost.max(f64::MIN_POSITIVE)) * groups as f64) as usize;
            let g = g.min(groups - 1);
            group_of[p] = g as u32 + 1;
            group_cost[g] += cost(p);
            before += cost(p);
        }
        let wave_len = n.div_ceil(FLOW_WAVES).max(MIN_WAVE_PORTALS);
        let mut wave_of = vec![0u32; n];
        for (i, &p) in order.iter().enumerate() {
            wave_of[p] = (i / wave_len) as u32;
        }
        let waves = n.div_ceil(wave_len);
        let mut later_groups = vec![0u64; waves];
        for w in (0..waves.saturating_sub(1)).rev() {
            let next = &order[(w + 1) * wave_len..((w + 2) * wave_len).min(n)];
            later_groups[w] =
                later_groups[w + 1] | next.iter().fold(0, |m, &p| m | 1 << group_of[p]);
        }
        FlowPlan {
            order,
            wave_len,
            wave_of,
            group_of,
            group_cost,
            later_groups,
        }
    }

    /// How many final groups the plan has: the most shards that can share the final work.
    pub fn groups(&self) -> usize {
        self.group_cost.len()
    }

    /// Every wave in run order.
    pub fn waves(&self) -> impl Iterator<Item = &[usize]> {
        self.order.chunks(self.wave_len)
    }

    /// Whether the flow of `base` may use the finished flow of `portal` as a bound: one of an
    /// earlier wave, shared or of the same final group.
    #[inline]
    pub fn bounds(&self, base: usize, portal: usize) -> bool {
        let group = self.group_of[portal];
        self.wave_of[portal] < self.wave_of[base] && (group == 0 || group == self.group_of[base])
    }

    /// Whether every flow of a later wave than `portal`'s may use its finished flow as a bound
    /// ([`FlowPlan::bounds`]): once that wave is over and the flow is done, nothing reads the
    /// portal's mightsee any more.
    pub fn bounds_every_later_flow(&self, portal: usize) -> bool {
        let group = self.group_of[portal];
        group == 0 || self.later_groups[self.wave_of[portal] as usize] & !(1 << group) == 0
    }

    /// Whether every shard runs `portal`'s flow.
    pub fn is_shared(&self, portal: usize) -> bool {
        self.group_of[portal] == 0
    }

    /// The final groups (numbered from 1) each of `shards` shards runs, balanced by estimated
    /// cost: costliest group first, each to the shard with the least work so far (the lowest
    /// index on a tie).
    pub fn shard_groups(&self, shards: usize) -> Vec<Vec<u32>> {
        let mut by_cost: Vec<usize> = (0..self.group_cost.len()).collect();
        by_cost.sort_by(|&a, &b| {
            self.group_cost[b]
                .total_cmp(&self.group_cost[a])
                .then(a.cmp(&b))
        });
        let mut groups = vec![Vec::new(); shards.max(1)];
        let mut load = vec![0.0f64; groups.len()];
        for g in by_cost {
            let (least, _) = load
                .iter()
                .enumerate()
                .fold(
                    (0, f64::INFINITY),
                    |best, (i, &l)| {
                        if l < best.1 { (i, l) } else { best }
                    },
                );
            load[least] += self.group_cost[g];
            groups[least].push(g as u32 + 1);
        }
        groups
    }

    /// By portal: whether `shard` runs its flow (the shared ones and its groups').
    pub fn runs(&self, shard: Shard) -> Vec<bool> {
        let mine = &self.shard_groups(shard.count)[shard.index];
        self.group_of
            .iter()
            .map(|g| *g == 0 || mine.contains(g))
            .collect()
    }

    /// The portals `shard` hands results on for: its groups', and (for the first shard) the
    /// shared ones, which every shard runs but only the first hands on.
    pub fn owned(&self, shard: Shard) -> Vec<usize> {
        let mine = &self.shard_groups(shard.count)[shard.index];
        (0..self.group_of.len())
            .filter(|&p| {
                let g = self.group_of[p];
                if g == 0 {
                    shard.index == 0
                } else {
                    mine.contains(&g)
                }
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sets(counts: &[usize]) -> Vec<BitSet> {
        let n = counts.iter().max().copied().unwrap_or(0) + 1;
        counts
            .iter()
            .map(|&c| {
                let mut s = BitSet::new(n);
                (0..c).for_each(|i| s.insert(i));
                s
            })
            .collect()
    }

    #[test]
    fn shard_parses_k_of_n_and_refuses_the_rest() {
        assert_eq!(Shard::parse("2/4"), Ok(Shard { index: 1, count: 4 }));
        assert_eq!(Shard::parse("1/1"), Ok(Shard::WHOLE));
        for bad in ["0/4", "5/4", "4", "a/b", "1/0", ""] {
            assert!(Shard::parse(bad).is_err(), "{bad}");
        }
        assert_eq!(Shard { index: 2, count: 3 }.to_string(), "3/3");
    }

    #[test]
    fn a_map_too_small_to_shard_gets_one_group_bounded_by_every_earlier_wave() {
        let counts: Vec<usize> = (0..400).map(|i| (i * 37) % 101).collect();
        let plan = FlowPlan::new(&sets(&counts), Grouping::Auto);
        assert_eq!(plan.groups(), 1);
        for base in 0..400 {
            for q in (0..400).step_by(7) {
                assert_eq!(plan.bounds(base, q), plan.wave_of[q] < plan.wave_of[base]);
            }
        }
        assert_eq!(plan.shard_groups(4), [vec![1], vec![], vec![], vec![]]);
    }

    #[test]
    fn the_costliest_portals_are_final_and_the_waves_cover_every_portal_once() {
        let mightsee = sets(&[5, 1, 90, 3, 40, 2, 0, 70, 8, 8]);
        let plan = FlowPlan::new(&mightsee, Grouping::Always);
        assert!(!plan.is_shared(2) && !plan.is_shared(7));
        assert!(plan.is_shared(6) && plan.is_shared(1));
        let mut all: Vec<usize> = plan.waves().flatten().copied().collect();
        all.sort();
        assert_eq!(all, (0..10).collect::<Vec<_>>());
        assert_eq!(FlowPlan::new(&[], Grouping::Auto).waves().count(), 0);
    }

    #[test]
    fn flows_are_bounded_by_earlier_waves_of_their_own_group_or_shared_ones() {
        let counts: Vec<usize> = (0..4000).map(|i| (i * 37) % 4001).collect();
        let mightsee = sets(&counts);
        let plan = FlowPlan::new(&mightsee, Grouping::Always);
        let groups: std::collections::BTreeSet<u32> = plan.group_of.iter().copied().collect();
        assert_eq!(groups.len(), FINAL_GROUPS + 1, "{groups:?}");
        for base in (0..4000).step_by(7) {
            for q in (0..4000).step_by(13) {
                let allowed = plan.wave_of[q] < plan.wave_of[base]
                    && (plan.is_shared(q) || plan.group_of[q] == plan.group_of[base]);
                assert_eq!(plan.bounds(base, q), allowed);
                // A shared flow never waits on a final one: every shard can run it alone.
                if plan.is_shared(base) && plan.bounds(base, q) {
                    assert!(plan.is_shared(q));
                }
            }
        }
    }

    #[test]
    fn a_flow_that_bounds_every_later_flow_does_bound_each() {
        for (n, grouping) in [(400, Grouping::Auto), (4000, Grouping::Always)] {
            let counts: Vec<usize> = (0..n).map(|i| (i * 37) % (n + 1)).collect();
            let plan = FlowPlan::new(&sets(&counts), grouping);
            let mut freed = 0;
            for q in 0..n {
                let every = (0..n)
                    .filter(|&base| plan.wave_of[base] > plan.wave_of[q])
                    .all(|base| plan.bounds(base, q));
                assert_eq!(plan.bounds_every_later_flow(q), every, "{n} portals: {q}");
                freed += usize::from(every);
            }
            // Shared portals always; in one group, every portal.
            assert!(freed >= (0..n).filter(|&p| plan.is_shared(p)).count());
            assert_eq!(freed == n, plan.groups() == 1, "{n}");
        }
    }

    #[test]
    fn shards_are_balanced_by_cost_and_together_own_every_portal_once() {
        let counts: Vec<usize> = (0..2000).map(|i| (i * 37) % 5001).collect();
        let mightsee = sets(&counts);
        let plan = FlowPlan::new(&mightsee, Grouping::Always);
        let biggest = plan.group_cost.iter().copied().fold(0.0, f64::max);
        for count in [1, 2, 3, 4, 7, 50] {
            let groups = plan.shard_groups(count);
            let loads: Vec<f64> = groups
                .iter()
                .map(|g| g.iter().map(|&g| plan.group_cost[g as usize - 1]).sum())
                .collect();
            let (lo, hi) = loads.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
            // Greedy by cost: no shard exceeds another by more than one group's cost.
            assert!(hi - lo <= biggest + 1e-9, "{count}: {loads:?}");
            let mut all: Vec<usize> = (0..count)
                .flat_map(|index| plan.owned(Shard { index, count }))
                .collect();
            all.sort();
            assert_eq!(all, (0..2000).collect::<Vec<_>>(), "{count} shards");
            for index in 0..count {
                let shard = Shard { index, count };
                let runs = plan.runs(shard);
                assert!(plan.owned(shard).iter().all(|&p| runs[p]));
                assert!((0..2000).all(|p| !plan.is_shared(p) || runs[p]));
            }
        }
    }
}
