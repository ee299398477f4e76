//! Criterion benchmarks of the parent planning step, stage by stage, on a
//! mid-episode knowledge map of the built-in office (800 × 600 cells, 20 m range),
//! and of a whole episode on the built-in site.
//!
//! `cargo bench -p cpsplan --bench planning`
//!
//! The `site_team` group times the planning step with two children (Eq. 1, AND
//! regions, Eq. 2, subgoals, Voronoi paths) on two site states, one whose move is a
//! single cycle and one that retrieves subgoals, and its dearest stages.
//!
//! These groups plan for the parent alone (`children.count = 0`); `episode` also
//! runs the site with the default team (`site_seed0_team`).
//!
//! The knowledge map is made deterministically: an office episode (seed 0) stopped
//! after 15 scans; the parent stands where the 15th scan was taken. A second group
//! repeats the two dearest stages after 100 scans, when most of the floor is known
//! and the travel-distance sweep covers nearly the whole grid.

use std::hint::black_box;
use std::time::Duration;

use criterion::measurement::WallTime;
use criterion::{criterion_group, criterion_main, BenchmarkGroup, Criterion};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use cpsplan::accuracy::{Chain, Instrument, Model, Objective};
use cpsplan::children::{and_region, ChildReach, CycleParams};
use cpsplan::config::ChildStrategy;
use cpsplan::geom::{Cell, Point};
use cpsplan::grid::travel::sweep;
use cpsplan::grid::{Traversability, UNREACHED};
use cpsplan::mission::plan_step;
use cpsplan::mission::Groundwork;
use cpsplan::motion::gvd;
use cpsplan::parent::{band, border_cells, kmeans, plan_parent};
use cpsplan::sensing::{expected_gain, mutual_view};
use cpsplan::subgoals::VisibilityGraph;
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::{run_episode, run_episode_with, Config, GridGeometry, OccupancyGrid};

/// The office knowledge map after 15 scans, the parent's cell, the last plan's
/// target cell and its band samples (cell units).
struct MidEpisode {
    config: Config,
    knowledge: OccupancyGrid,
    parent: Cell,
    target: Cell,
    samples: Vec<[f64; 2]>,
}

fn mid_episode(scans: usize) -> MidEpisode {
    let map = BuiltinMap::Office;
    let mut config = Config::default();
    config.children.count = 0;
    config.mission.max_scans = scans;
    let truth = map.generate(0);
    let episode = run_episode(&truth, map.default_start(), &config, |_| {}).expect("episode");
    let knowledge = episode.knowledge.expect("knowledge map");
    let last = episode.steps.last().expect("at least one step");
    let g = *knowledge.geometry();
    let samples = last
        .plan
        .samples
        .iter()
        .map(|p| {
            [
                (p.x - g.origin.x) / g.resolution,
                (p.y - g.origin.y) / g.resolution,
            ]
        })
        .collect();
    MidEpisode {
        config,
        parent: last.cell,
        target: last.plan.target().expect("a target").cell,
        knowledge,
        samples,
    }
}

/// The travel-distance sweep from the parent over its passable cells.
fn bench_reach_sweep(
    group: &mut BenchmarkGroup<'_, WallTime>,
    g: &GridGeometry,
    trav: &Traversability,
    parent: Cell,
) {
    group.bench_function("reach_sweep", |b| {
        b.iter(|| sweep(g, black_box(&trav.passable), &[g.index(parent)], UNREACHED))
    });
}

fn stages(c: &mut Criterion) {
    let m = mid_episode(15);
    let k = &m.knowledge;
    let g = *k.geometry();
    let config = &m.config;
    let radius = config.robot.radius;

    let mut group = c.benchmark_group("office_mid_episode");
    group
        .sample_size(30)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));

    group.bench_function("traversability", |b| {
        b.iter(|| Traversability::new(black_box(k), radius, m.parent))
    });
    let trav = Traversability::new(k, radius, m.parent);
    bench_reach_sweep(&mut group, &g, &trav, m.parent);
    group.bench_function("border_and_band", |b| {
        b.iter(|| {
            let border = border_cells(black_box(k));
            band(k, &border, config.parent.band_width)
        })
    });
    group.bench_function("expected_gain", |b| {
        b.iter(|| expected_gain(black_box(k), m.target, config.range_cells(), usize::MAX))
    });
    let border = border_cells(k);
    let band_cells = band(k, &border, config.parent.band_width);
    let band_area = band_cells.len() as f64 * g.resolution * g.resolution;
    let clusters = ((band_area / config.parent.cluster_area).ceil() as usize)
        .clamp(1, config.parent.max_clusters);
    group.bench_function("kmeans", |b| {
        b.iter(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            kmeans(
                black_box(&m.samples),
                clusters,
                config.parent.kmeans_iterations,
                &mut rng,
            )
        })
    });
    bench_parent_round(&mut group, &m);
    group.finish();
}

/// The parent's whole round with each planner, and its gain estimate.
fn bench_parent_round(group: &mut BenchmarkGroup<'_, WallTime>, m: &MidEpisode) {
    let (k, config) = (&m.knowledge, &m.config);
    group.bench_function("plan_parent", |b| {
        b.iter(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            plan_parent(black_box(k), m.parent, config, &mut rng)
        })
    });
    group.bench_function("gain_estimate", |b| {
        b.iter(|| cpsplan::sensing::GainEstimate::new(black_box(k), config))
    });
    // In an episode the gain estimate's field, the border, the band and the
    // drivable cells are kept across scans.
    let near = cpsplan::sensing::NearField::new(k, config);
    let frontier = cpsplan::parent::Frontier::new(k, &config.parent);
    let drivable = cpsplan::grid::Drivable::new(k, config.robot.radius);
    let kept = cpsplan::parent::Kept {
        near: &near,
        frontier: &frontier,
        drivable: &drivable,
        truth: None,
    };
    group.bench_function("plan_parent_kept_field", |b| {
        b.iter(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            cpsplan::parent::plan_parent_with_field(
                black_box(k),
                m.parent,
                config,
                &mut rng,
                Some(kept),
            )
        })
    });
    let mut tour = config.clone();
    tour.parent.planner = cpsplan::config::Planner::Tour;
    group.bench_function("plan_parent_tour", |b| {
        b.iter(|| {
            let mut rng = ChaCha8Rng::seed_from_u64(7);
            plan_parent(black_box(k), m.parent, &tour, &mut rng)
        })
    });
}

fn late_stages(c: &mut Criterion) {
    let m = mid_episode(100);
    let k = &m.knowledge;
    let g = *k.geometry();
    let config = &m.config;
    let mut group = c.benchmark_group("office_late_episode");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    let trav = Traversability::new(k, config.robot.radius, m.parent);
    bench_reach_sweep(&mut group, &g, &trav, m.parent);
    bench_parent_round(&mut group, &m);
    group.finish();
}

fn episode(c: &mut Criterion) {
    let map = BuiltinMap::Site;
    let truth = map.generate(0);
    let mut alone = Config::default();
    alone.children.count = 0;
    let team = Config::default();
    let mut group = c.benchmark_group("episode");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_secs(1))
        .measurement_time(Duration::from_secs(8));
    for (name, config) in [("site_seed0", &alone), ("site_seed0_team", &team)] {
        group.bench_function(name, |b| {
            b.iter(|| {
                run_episode(black_box(&truth), map.default_start(), config, |_| {})
                    .expect("episode")
                    .summary
            })
        });
    }
    group.finish();
}

/// A site (seed 0) state with two children: the knowledge map the step planned
/// on, the parent's and the children's cells, and whether the step's move
/// retrieved subgoals.
struct TeamState {
    knowledge: OccupancyGrid,
    parent: Point,
    children: Vec<Point>,
    retrieved: bool,
    target: Option<Cell>,
}

/// The first step of the site episode with two children whose move retrieved
/// subgoals (`retrieved`), or the first after the third scan whose move did not.
fn team_state(config: &Config, retrieved: bool) -> TeamState {
    let map = BuiltinMap::Site;
    let truth = map.generate(0);
    let mut found: Option<TeamState> = None;
    run_episode_with(&truth, map.default_start(), config, |step, known| {
        let target = step.movement.target.map(|i| step.plan.candidates[i].cell);
        if found.is_none()
            && step.scan > 3
            && target.is_some()
            && step.movement.subgoal_retrieval == retrieved
        {
            found = Some(TeamState {
                knowledge: known.clone(),
                parent: step.position,
                children: step.children.clone(),
                retrieved,
                target,
            });
        }
    })
    .expect("episode");
    found.expect("such a step")
}

fn team(c: &mut Criterion) {
    let mut config = Config::default();
    config.children.count = 2;
    let params = CycleParams::from_config(&config);
    let mut group = c.benchmark_group("site_team");
    group
        .sample_size(20)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(4));
    for retrieved in [false, true] {
        let s = team_state(&config, retrieved);
        let k = &s.knowledge;
        let g = *k.geometry();
        let parent = g.world_to_cell(s.parent).expect("parent on the map");
        let name = if s.retrieved { "subgoals" } else { "direct" };
        group.bench_function(format!("plan_step_{name}"), |b| {
            b.iter(|| plan_step(black_box(k), s.parent, &s.children, &config).expect("plan"))
        });
        let mut min_error = config.clone();
        min_error.children.strategy = ChildStrategy::MinError;
        group.bench_function(format!("plan_step_{name}_min_error"), |b| {
            b.iter(|| plan_step(black_box(k), s.parent, &s.children, &min_error).expect("plan"))
        });
        if retrieved {
            let trav = Traversability::new(k, config.robot.radius, parent);
            group.bench_function("visibility_graph", |b| {
                b.iter(|| VisibilityGraph::build(black_box(k), &trav))
            });
            continue;
        }
        group.bench_function("groundwork", |b| {
            b.iter(|| {
                Groundwork::new(
                    black_box(k),
                    parent,
                    config.robot.radius,
                    &params,
                    None,
                    None,
                )
            })
        });
        let trav = Traversability::new(k, config.robot.radius, parent);
        group.bench_function("gvd", |b| b.iter(|| gvd(black_box(k), &trav)));
        let target = s.target.expect("a target");
        let child = g.world_to_cell(s.children[0]).expect("child on the map");
        let reach = ChildReach::new(k, child, params.child_radius);
        group.bench_function("and_region", |b| {
            b.iter(|| {
                let mutual = mutual_view(black_box(k), parent, target, params.link, |_| true);
                and_region(&mutual, &reach)
            })
        });
    }
    group.finish();
}

/// The CPS chain: one cycle of the first-order propagation (two children), and
/// one evaluation of the min-error objective.
fn accuracy(c: &mut Criterion) {
    let model = Model::new(Instrument::from_config(&Config::default().instrument));
    let mut group = c.benchmark_group("accuracy");
    group
        .sample_size(50)
        .warm_up_time(Duration::from_millis(300))
        .measurement_time(Duration::from_secs(2));
    let mut chain = Chain::new(model, Point::new(0.0, 0.0), 2);
    chain
        .cycle(
            Point::new(10.0, 0.0),
            &[Point::new(5.0, 4.0), Point::new(5.0, -4.0)],
            &[true, true],
        )
        .expect("cycle");
    let kids = [Point::new(14.0, 5.0), Point::new(15.0, -4.0)];
    group.bench_function("chain_cycle", |b| {
        b.iter(|| {
            let mut c = chain.clone();
            c.cycle(black_box(Point::new(20.0, 1.0)), &kids, &[true, true])
                .expect("cycle")
        })
    });
    let objective = Objective::new(&chain, Point::new(20.0, 1.0), &[]).expect("objective");
    let j = objective.mover_info(kids[0]) + objective.mover_info(kids[1]);
    group.bench_function("objective_value", |b| {
        b.iter(|| objective.value(black_box(&j)))
    });
    group.bench_function("mover_info", |b| {
        b.iter(|| objective.mover_info(black_box(kids[0])))
    });
    group.finish();
}

criterion_group!(benches, stages, late_stages, episode, team, accuracy);
criterion_main!(benches);
