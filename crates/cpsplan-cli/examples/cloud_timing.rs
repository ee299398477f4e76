//! Timings of the 3D data paths (docs/PERFORMANCE.md "Point clouds"): the
//! registered model of the default episode (building it, encoding it as LAS,
//! LAZ and PLY), and `grid`'s reading and projection of the clouds given on the
//! command line.
//!
//! `cargo run --release -p cpsplan-cli --example cloud_timing -- [CLOUD...]`

use std::time::Instant;

use cpsplan::model::{build_model, ModelPoint};
use cpsplan::world::builtin::BuiltinMap;
use cpsplan::world::projection::{project, BeamOrigin, ProjectionParams};
use cpsplan::{run_episode, Config};
use cpsplan_cli::formats::cloud::{
    encode_las, encode_ply, read_cloud, CloudError, CloudReadOptions,
};

/// The best of `n` runs of `f`, seconds, and its last result.
fn best<T>(n: usize, mut f: impl FnMut() -> T) -> (f64, T) {
    let mut out = None;
    let mut best = f64::INFINITY;
    for _ in 0..n {
        let t = Instant::now();
        out = Some(f());
        best = best.min(t.elapsed().as_secs_f64());
    }
    (best, out.expect("at least one run"))
}

type Encoder = fn(&[ModelPoint]) -> Result<Vec<u8>, CloudError>;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut config = Config::default();
    config.accuracy.monte_carlo_runs = 20;
    let truth = BuiltinMap::Site.generate(0);
    let (episode_s, episode) = best(1, || {
        run_episode(&truth, BuiltinMap::Site.default_start(), &config, |_| {})
    });
    let episode = episode?;
    println!("default episode with 20 Monte Carlo runs: {episode_s:.3} s");
    let (model_s, _) = best(5, || build_model(&truth, &episode, &config, |_, _| {}));
    let mut points = Vec::new();
    build_model(&truth, &episode, &config, |_, p| {
        points.extend_from_slice(p)
    })?;
    println!(
        "model: {} points, built with its accuracy in {:.3} s ({:.1} M points/s)",
        points.len(),
        model_s,
        points.len() as f64 / model_s / 1e6
    );
    let encoders: [(&str, Encoder); 3] = [
        ("LAS", |p| encode_las(p, false)),
        ("LAZ", |p| encode_las(p, true)),
        ("PLY", encode_ply),
    ];
    for (name, f) in encoders {
        let (s, bytes) = best(5, || f(&points));
        let bytes = bytes?;
        println!(
            "{name}: {:.3} s, {:.1} M points/s, {:.1} MB",
            s,
            points.len() as f64 / s / 1e6,
            bytes.len() as f64 / 1e6
        );
    }
    for path in std::env::args().skip(1) {
        let options = CloudReadOptions::default();
        let (read_s, cloud) = best(5, || read_cloud(path.as_ref(), &options, &mut |_, _| {}));
        let cloud = cloud?;
        let n = cloud.points.len() as f64;
        let origins: Vec<BeamOrigin> = cloud
            .scans
            .iter()
            .filter_map(|s| {
                Some(BeamOrigin {
                    points: s.points.clone(),
                    origin: s.origin?,
                })
            })
            .collect();
        let mut line = format!(
            "{path}: {n} points, read {:.1} M points/s",
            n / read_s / 1e6
        );
        for beams in [false, true]
            .into_iter()
            .filter(|&b| !b || !origins.is_empty())
        {
            let params = ProjectionParams {
                free_from_scans: beams,
                ..ProjectionParams::default()
            };
            let (s, p) = best(5, || {
                project(&cloud.points, &origins, &params, &config, |_, _| {})
            });
            let cells = p?.grid.geometry().len();
            line += &format!(
                "; projected{} {:.1} M points/s ({} cells)",
                if beams { " with beams" } else { "" },
                n / s / 1e6,
                cells
            );
        }
        println!("{line}");
    }
    Ok(())
}
