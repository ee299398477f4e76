//! Tests of the configuration's defaults, presets and parsing.

use super::*;

#[test]
fn defaults_are_valid_and_the_papers() {
    let c = Config::default();
    c.validate().unwrap();
    assert_eq!((c.parent.alpha, c.parent.beta), (0.01, 0.001));
    assert_eq!((c.resolution, c.scanner.range), (0.1, 20.0));
}

#[test]
fn negative_range_is_rejected_by_name() {
    let mut c = Config::default();
    c.scanner.range = -1.0;
    let e = c.validate().unwrap_err();
    assert_eq!(e.key(), "scanner.range");
    assert!(e.to_string().contains("scanner.range"));
}

#[test]
fn the_paper_preset_sets_its_keys_unless_they_are_set() {
    let paper = Config::preset(Preset::Paper);
    assert_eq!(paper.preset, Some(Preset::Paper));
    assert_eq!(paper.parent.planner, Planner::Paper);
    assert_eq!(paper.children.strategy, ChildStrategy::Balanced);
    assert_eq!(
        (
            paper.parent.min_gain_m2,
            paper.parent.min_gain_share,
            paper.parent.calibration_window
        ),
        (0.0, 0.0, 0)
    );
    let mut c = Config::default();
    c.parent.planner = Planner::Tour;
    c.children.strategy = ChildStrategy::MinError;
    Preset::Paper.apply(&mut c, |k| k == "children.strategy");
    assert_eq!(c.parent.planner, Planner::Paper);
    assert_eq!(c.children.strategy, ChildStrategy::MinError);
    for p in Preset::ALL {
        let back: Preset = serde_json::from_str(&format!("\"{}\"", p.name())).unwrap();
        assert_eq!(back, p);
        assert!(!p.keys().is_empty());
    }
}

#[test]
fn json_round_trip() {
    let c = Config::default();
    let s = serde_json::to_string(&c).unwrap();
    let back: Config = serde_json::from_str(&s).unwrap();
    assert_eq!(c, back);
    let partial: Config = serde_json::from_str(r#"{"parent":{"alpha":0}}"#).unwrap();
    assert_eq!(partial.parent.alpha, 0.0);
    assert_eq!(partial.parent.beta, 0.001);
}

/// The names configs and the command line use are the serialized names.
#[test]
fn preset_and_strategy_names_parse() {
    for m in InstrumentModel::ALL {
        let c: InstrumentConfig =
            serde_json::from_str(&format!(r#"{{"model":"{}"}}"#, m.name())).unwrap();
        assert_eq!(c.model, m);
    }
    for st in ChildStrategy::ALL {
        let c: ChildrenConfig =
            serde_json::from_str(&format!(r#"{{"strategy":"{}"}}"#, st.name())).unwrap();
        assert_eq!(c.strategy, st);
    }
}
