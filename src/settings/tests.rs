//! The settings' merge, checks and derived runs.

use super::*;

#[test]
fn the_command_line_replaces_a_step_count_by_a_step_and_keeps_the_rest() {
    let file = Request {
        steps: Some(100),
        until: Some(2.0),
        alpha: Some(-0.2),
        ..Request::default()
    };
    let r = file.overlaid(&Request {
        dt: Some(0.01),
        ..Request::default()
    });
    assert_eq!(
        (r.dt, r.steps, r.until, r.alpha),
        (Some(0.01), None, Some(2.0), Some(-0.2))
    );
}

#[test]
fn ranges_are_checked_once_for_every_setting() {
    let r = Request {
        alpha: Some(-0.5),
        rho_inf: Some(1.5),
        dt: Some(-1.0),
        every: Some(0),
        tolerance: Some(0.5),
        ..Request::default()
    };
    let fields: Vec<Field> = r.check().iter().map(|i| i.field).collect();
    assert_eq!(
        fields,
        [
            Field::Alpha,
            Field::RhoInf,
            Field::Dt,
            Field::Tolerance,
            Field::Every
        ]
    );
    assert!(Request {
        alpha: Some(-1.0 / 3.0),
        rho_inf: Some(0.0),
        ..Request::default()
    }
    .check()
    .is_empty());
}

#[test]
fn a_period_is_cut_into_whole_steps_no_longer_than_dt() {
    let s = Settings {
        dt: 0.3,
        ..Settings::default()
    }
    .over(1.0);
    assert_eq!(s.steps, 4);
    assert!((s.dt - 0.25).abs() < 1e-15 && s.until == 1.0);
}
