//! The state an episode keeps across scans instead of recomputing it gives the
//! planner exactly what a from-scratch computation gives: on every built-in
//! map, at every step, each candidate's gain estimate equals the estimate of
//! the step's knowledge map computed afresh, and so do the round's border, band
//! and samples, each candidate's `R`, clearance and travel distance, the border
//! groups' viewpoints and the Voronoi diagram the children drive along.

use cpsplan::config::Planner;
use cpsplan::sensing::GainEstimate;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode_with, Config};

#[test]
fn kept_gain_field_equals_a_fresh_one_on_the_builtin_maps() {
    for map in BuiltinMap::ALL {
        for planner in Planner::ALL {
            let truth = map.generate(0);
            let mut config = Config::default();
            config.children.count = 0;
            config.mission.max_scans = 60;
            config.parent.planner = planner;
            let range = config.range_cells();
            let mut checked = 0usize;
            run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
                let mut round = config.clone();
                round.parent.gain_scale = step.gain_scale;
                let fresh = GainEstimate::new(knowledge, &round);
                for c in step.plan.candidates.iter().filter(|c| c.r == 1) {
                    let want = fresh.at(knowledge, c.cell, range);
                    assert_eq!(
                        (c.s_cells, c.gain_m2),
                        (want.s_cells, want.m2),
                        "{map:?} {planner:?} scan {} candidate at {:?}",
                        step.scan,
                        c.cell
                    );
                    checked += 1;
                }
            })
            .expect("the episode runs");
            assert!(
                checked > 50,
                "{map:?} {planner:?}: only {checked} candidates"
            );
        }
    }
}

/// The border, the band and the drivable cells kept across scans
/// ([`cpsplan::parent::Frontier`], [`cpsplan::grid::Drivable`]): at every step of
/// episodes on the built-in maps, alone and with the default team, the round's
/// border and band sizes, its samples and every candidate's `R`, clearance and
/// `L` are those of a border, band, traversability and travel sweep computed
/// afresh from the step's knowledge map; so are its viewpoint candidates (the
/// border groups' looks kept across scans, `Frontier::viewpoints`), those of a
/// viewpoint search on the fresh border, drivable cells and sweep.
#[test]
fn kept_border_band_and_drivable_cells_equal_fresh_ones_on_the_builtin_maps() {
    use cpsplan::grid::travel::sweep;
    use cpsplan::grid::{Traversability, UNREACHED};
    use cpsplan::parent::Frontier;
    for map in BuiltinMap::ALL {
        for children in [0, 2] {
            let truth = map.generate(0);
            let mut config = Config::default();
            config.children.count = children;
            config.mission.max_scans = 40;
            let (mut checked, mut viewpoints) = (0usize, 0usize);
            run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
                let g = *knowledge.geometry();
                let frontier = Frontier::new(knowledge, &config.parent);
                let plan = &step.plan;
                let at = format!("{map:?} children {children} scan {}", step.scan);
                assert_eq!(plan.border_cells, frontier.significant().len(), "{at}");
                if plan.band_cells > 0 {
                    assert_eq!(plan.band_cells, frontier.band().len(), "{at}");
                }
                for p in &plan.samples {
                    let cell = g.world_to_cell(*p).expect("a sample on the grid");
                    assert!(
                        frontier.band().binary_search(&g.index(cell)).is_ok(),
                        "{at}: sample {p:?} off the band"
                    );
                }
                let trav = Traversability::new(knowledge, config.robot.radius, step.cell);
                let field = sweep(&g, &trav.passable, &[g.index(step.cell)], UNREACHED);
                for c in &plan.candidates {
                    let i = g.index(c.cell);
                    let reachable = trav.traversable[i] && field.reached(i);
                    assert_eq!(c.r == 1, reachable, "{at}: R of {:?}", c.cell);
                    if reachable {
                        let clearance = (trav.clearance_at(i) as f64).min(config.scanner.range);
                        assert_eq!(c.clearance_m, clearance, "{at}: clearance of {:?}", c.cell);
                        assert_eq!(c.l_m, field.metres(i), "{at}: L of {:?}", c.cell);
                    }
                    checked += 1;
                }
                let range = config.range_cells();
                viewpoints +=
                    fresh_viewpoints_match(step, knowledge, &frontier, &trav, &field, range);
            })
            .expect("the episode runs");
            assert!(
                checked > 40,
                "{map:?} children {children}: only {checked} candidates"
            );
            assert!(
                viewpoints > 20,
                "{map:?} children {children}: only {viewpoints} viewpoints"
            );
        }
    }
}

/// The GVD's obstacle side kept across scans ([`cpsplan::motion::VoronoiField`]):
/// at every step of team episodes on the built-in maps, the diagram it gives for
/// the robots' drivable cells equals the diagram computed afresh from the step's
/// knowledge map.
#[test]
fn kept_voronoi_field_gives_the_fresh_diagram_on_the_builtin_maps() {
    use cpsplan::grid::{CellState, OccupancyGrid, Traversability};
    use cpsplan::motion::{gvd, VoronoiField};
    for map in BuiltinMap::ALL {
        let truth = map.generate(0);
        let mut config = Config::default();
        config.mission.max_scans = 30;
        let mut before = OccupancyGrid::filled(*truth.geometry(), CellState::Unknown);
        let mut kept = VoronoiField::new(&before);
        let mut checked = 0usize;
        run_episode_with(&truth, map.default_start(), &config, |step, knowledge| {
            let changed: Vec<usize> = (0..knowledge.cells().len())
                .filter(|&i| knowledge.cells()[i] != before.cells()[i])
                .collect();
            kept.update(knowledge, &changed);
            before = knowledge.clone();
            let trav = Traversability::new(knowledge, config.children.radius, step.cell);
            let (a, b) = (kept.diagram(knowledge, &trav), gvd(knowledge, &trav));
            let at = format!("{map:?} scan {}", step.scan);
            assert!(a.count() > 0, "{at}: an empty diagram");
            assert_eq!(a.skeleton, b.skeleton, "{at}: skeleton");
            assert_eq!(a.clearances(), b.clearances(), "{at}: clearance");
            assert_eq!(a.edge_component, b.edge_component, "{at}: edge components");
            checked += 1;
        })
        .expect("the episode runs");
        assert!(checked > 5, "{map:?}: only {checked} steps");
    }
}

/// Asserts that the round's viewpoint candidates are those of a fresh viewpoint
/// search on `frontier`, `trav` and `field` (the step's own, computed afresh);
/// the one a tour's hill climb moved is checked by count only. Returns how many
/// were compared by cell.
fn fresh_viewpoints_match(
    step: &cpsplan::mission::Step,
    knowledge: &cpsplan::OccupancyGrid,
    frontier: &cpsplan::parent::Frontier,
    trav: &cpsplan::grid::Traversability,
    field: &cpsplan::grid::DistanceField,
    range: f64,
) -> usize {
    use cpsplan::parent::{viewpoints, CandidateOrigin};
    use std::collections::HashSet;
    let plan = &step.plan;
    let at = format!("scan {} at {:?}", step.scan, step.cell);
    let valid = |i: usize| trav.traversable[i] && field.reached(i);
    let cost = |i: usize| field.metres(i).unwrap_or(f64::INFINITY);
    let mut seen: HashSet<_> = plan
        .candidates
        .iter()
        .filter(|c| {
            matches!(
                c.origin,
                CandidateOrigin::Centroid | CandidateOrigin::Snapped
            )
        })
        .map(|c| c.cell)
        .collect();
    let want: Vec<_> = viewpoints(knowledge, frontier.significant(), range, valid, cost)
        .into_iter()
        .map(|v| v.cell)
        .filter(|&c| seen.insert(c))
        .collect();
    let got: Vec<_> = plan
        .candidates
        .iter()
        .filter(|c| c.origin == CandidateOrigin::Viewpoint)
        .collect();
    assert_eq!(got.len(), want.len(), "{at}: viewpoints");
    let mut compared = 0;
    for (c, &w) in got.iter().zip(&want) {
        if !c.refined {
            assert_eq!(c.cell, w, "{at}: a viewpoint");
            compared += 1;
        }
    }
    compared
}
