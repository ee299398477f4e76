//! Greedy set cover with lazy evaluation (Minoux's accelerated greedy): the
//! station that sees the most targets not yet covered, again and again.
//!
//! A station's gain can only shrink as others are chosen, so a max-heap of stale
//! gains suffices: the top is re-evaluated, and taken when it is still at least
//! the next stale gain. The result equals plain greedy's (ties to the lower index).

use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// One greedy choice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Pick {
    /// Index of the station into the sets.
    pub station: usize,
    /// Targets it covered that no earlier pick had.
    pub gain: usize,
    /// Targets covered after it.
    pub covered: usize,
}

/// Greedy cover of the targets `0..targets` by `sets` (each a list of target
/// indices), until every target that any set holds is covered. Picks in order.
pub fn lazy_greedy<S: AsRef<[u32]>>(sets: &[S], targets: usize) -> Vec<Pick> {
    lazy_greedy_while(sets, targets, 1)
}

/// The picks of [`lazy_greedy`] as long as each adds at least `min_gain`
/// targets. A greedy cover's gains never grow from one pick to the next, so
/// the search stops once no set's bound reaches `min_gain` instead of covering
/// the rest.
pub fn lazy_greedy_while<S: AsRef<[u32]>>(
    sets: &[S],
    targets: usize,
    min_gain: usize,
) -> Vec<Pick> {
    let min_gain = min_gain.max(1);
    // The flags of a whole map's cells on a large map: kept for the next cover
    // and cleared where the picks set them, not allocated and zeroed each time.
    let mut kept = COVERED.with(|c| std::mem::take(&mut *c.borrow_mut()));
    if kept.len() < targets {
        kept.resize(targets, false);
    }
    let covered = &mut kept[..targets];
    let mut heap: BinaryHeap<(usize, Reverse<usize>)> = sets
        .iter()
        .enumerate()
        .filter(|(_, s)| !s.as_ref().is_empty())
        .map(|(j, s)| (s.as_ref().len(), Reverse(j)))
        .collect();
    let mut picks = Vec::new();
    let mut total = 0usize;
    while let Some((stale, Reverse(j))) = heap.pop() {
        if stale < min_gain {
            break;
        }
        let gain = sets[j]
            .as_ref()
            .iter()
            .filter(|&&t| !covered[t as usize])
            .count();
        if gain == 0 {
            continue;
        }
        let next = heap.peek().map_or(0, |&(g, _)| g);
        if gain < stale && gain < next {
            heap.push((gain, Reverse(j)));
            continue;
        }
        // Ties with the next stale gain: that one may tie or lose, and ties go to
        // the lower index, so re-check it if its index is lower.
        if gain == next {
            if let Some(&(_, Reverse(k))) = heap.peek() {
                if k < j && gain < stale {
                    heap.push((gain, Reverse(j)));
                    continue;
                }
            }
        }
        if gain < min_gain {
            break;
        }
        for &t in sets[j].as_ref() {
            covered[t as usize] = true;
        }
        total += gain;
        picks.push(Pick {
            station: j,
            gain,
            covered: total,
        });
    }
    for p in &picks {
        for &t in sets[p.station].as_ref() {
            covered[t as usize] = false;
        }
    }
    if kept.len() <= KEEP_TARGETS {
        COVERED.with(|c| *c.borrow_mut() = kept);
    }
    picks
}

/// The most targets whose flags a thread keeps for the next cover.
const KEEP_TARGETS: usize = 1 << 24;

thread_local! {
    /// Per target whether a pick covers it: all `false` between covers.
    static COVERED: std::cell::RefCell<Vec<bool>> = std::cell::RefCell::default();
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// Plain greedy: every gain recomputed every round, ties to the lower index.
    fn plain_greedy(sets: &[Vec<u32>], targets: usize) -> Vec<Pick> {
        let mut covered = vec![false; targets];
        let mut picks = Vec::new();
        let mut total = 0;
        loop {
            let best = sets
                .iter()
                .enumerate()
                .map(|(j, s)| (s.iter().filter(|&&t| !covered[t as usize]).count(), j))
                .max_by(|a, b| a.0.cmp(&b.0).then(b.1.cmp(&a.1)));
            match best {
                Some((gain, j)) if gain > 0 => {
                    for &t in &sets[j] {
                        covered[t as usize] = true;
                    }
                    total += gain;
                    picks.push(Pick {
                        station: j,
                        gain,
                        covered: total,
                    });
                }
                _ => return picks,
            }
        }
    }

    #[test]
    fn covers_a_textbook_instance_greedily() {
        // Greedy takes the big middle set first, then needs both halves.
        let sets = vec![vec![0, 1, 2, 3], vec![4, 5, 6, 7], vec![1, 2, 3, 4, 5, 6]];
        let p = lazy_greedy(&sets, 8);
        assert_eq!(p.iter().map(|p| p.station).collect::<Vec<_>>(), [2, 0, 1]);
        assert_eq!(p.last().map(|p| p.covered), Some(8));
    }

    proptest! {
        #[test]
        fn lazy_equals_plain_greedy(
            sets in prop::collection::vec(prop::collection::btree_set(0u32..40, 0..12), 1..25)
        ) {
            let sets: Vec<Vec<u32>> = sets.into_iter().map(|s| s.into_iter().collect()).collect();
            prop_assert_eq!(lazy_greedy(&sets, 40), plain_greedy(&sets, 40));
        }

        /// Two covers in a row on one thread: the second starts from the flags
        /// the first cleared.
        #[test]
        fn a_second_cover_starts_clear(
            sets in prop::collection::vec(prop::collection::vec(0u32..300, 0..40), 1..25)
        ) {
            let plain = plain_greedy(&sets, 300);
            prop_assert_eq!(&lazy_greedy(&sets, 300), &plain);
            prop_assert_eq!(&lazy_greedy(&sets, 300), &plain);
        }

        /// Stopped at a least gain: the plain greedy's picks up to the first
        /// that adds less.
        #[test]
        fn stopped_lazy_equals_the_plain_greedys_prefix(
            sets in prop::collection::vec(prop::collection::btree_set(0u32..40, 0..12), 1..25),
            min_gain in 0usize..8,
        ) {
            let sets: Vec<Vec<u32>> = sets.into_iter().map(|s| s.into_iter().collect()).collect();
            let prefix: Vec<Pick> = plain_greedy(&sets, 40)
                .into_iter()
                .take_while(|p| p.gain >= min_gain)
                .collect();
            prop_assert_eq!(lazy_greedy_while(&sets, 40, min_gain), prefix);
        }
    }
}
