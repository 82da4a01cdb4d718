//! MOBIL changes lanes exactly when its incentive and safety criteria hold. The expected
//! accelerations were computed by hand from the IDM's closed form (Treiber et al. 2000) with
//! the default parameters (a = 0.73 m/s², b = 1.67 m/s², T = 1.6 s, s₀ = 2 m, δ = 4, braking
//! capped at 8 m/s²), independently of this code (a separate short script, values quoted below).

use super::*;

const CAR_M: f64 = 4.5;

fn car(s_m: f64, speed_mps: f64, desired_speed_mps: f64) -> LaneDriver {
    LaneDriver {
        s_m,
        speed_mps,
        desired_speed_mps,
        length_m: CAR_M,
    }
}

fn alone(me: LaneDriver) -> Neighbourhood {
    Neighbourhood {
        me,
        leader_now: None,
        follower_now: None,
        leader_after: None,
        follower_after: None,
        leaving_ending_lane: false,
    }
}

fn close(actual: f64, expected: f64) {
    assert!((actual - expected).abs() < 1e-9, "{actual} vs {expected}");
}

#[test]
fn a_slow_leader_and_a_free_lane_beside_make_a_change() {
    // Me at 20 m/s (v₀ 30) 25.5 m behind a car at 15 m/s; the lane beside is empty.
    let n = Neighbourhood {
        leader_now: Some(car(30.0, 15.0, 15.0)),
        ..alone(car(0.0, 20.0, 30.0))
    };
    let a = change_accelerations(&IdmParams::default(), &n);
    // s* = 2 + 20·1.6 + 20·5 / (2·√(0.73·1.67)) = 79.285…; a = 0.73·(1 − (2/3)⁴ − (s*/25.5)²).
    close(a.me.0, -6.471194856506616);
    // Free road: 0.73·(1 − (2/3)⁴).
    close(a.me.1, 0.5858024691358025);
    let v = verdict(&MobilParams::default(), &a, false);
    close(v.incentive_mps2, 7.056997325642419);
    assert!(v.safe && v.change);
}

#[test]
fn a_change_that_would_make_the_new_follower_brake_hard_is_unsafe() {
    // As above, but a car at 25 m/s is 3.5 m behind the gap: after the change it would brake at
    // the IDM's cap, 8 m/s² > b_safe = 4 m/s².
    let n = Neighbourhood {
        leader_now: Some(car(30.0, 15.0, 15.0)),
        follower_after: Some(car(-8.0, 25.0, 30.0)),
        ..alone(car(0.0, 20.0, 30.0))
    };
    let a = change_accelerations(&IdmParams::default(), &n);
    let (now, after) = a.new_follower.unwrap();
    close(now, 0.3779552469135802);
    close(after, -8.0);
    let v = verdict(&MobilParams::default(), &a, false);
    assert!(v.incentive_mps2 > MobilParams::default().threshold_mps2);
    assert!(!v.safe && !v.change);
    // b_safe just above what the follower would need: safe, and the change happens only if
    // the incentive still clears the threshold.
    let lenient = MobilParams {
        safe_decel_mps2: 8.0,
        ..MobilParams::default()
    };
    let v = verdict(&lenient, &a, false);
    assert!(v.safe);
    assert_eq!(v.change, v.incentive_mps2 > lenient.threshold_mps2);
}

#[test]
fn politeness_weighs_the_new_followers_loss() {
    // Me at 20 m/s (v₀ 22) 55.5 m behind a car at 19.5 m/s: a_c = −0.1204, free: 0.2314, a
    // gain of 0.3518 m/s². A car at 22 m/s (v₀ 30) 35.5 m behind the gap would go from
    // 0.5189 to −1.3714 m/s²: safe (≥ −4), but a loss of 1.8903.
    let n = Neighbourhood {
        leader_now: Some(car(60.0, 19.5, 19.5)),
        follower_after: Some(car(-40.0, 22.0, 30.0)),
        ..alone(car(0.0, 20.0, 22.0))
    };
    let a = change_accelerations(&IdmParams::default(), &n);
    close(a.me.0, -0.12040331634645615);
    close(a.me.1, 0.23140017758349843);
    let (now, after) = a.new_follower.unwrap();
    close(now, 0.5188803950617284);
    close(after, -1.3713809289898524);
    let gain = 0.23140017758349843 + 0.12040331634645615;
    let loss = -1.3713809289898524 - 0.5188803950617284;
    // p = 0.2: 0.3518 − 0.2·1.8903 = −0.0262 < 0.1: no change.
    let v = verdict(&MobilParams::default(), &a, false);
    close(v.incentive_mps2, gain + 0.2 * loss);
    assert!(v.safe && !v.change);
    // An egoistic driver (p = 0) changes.
    let egoist = MobilParams {
        politeness: 0.0,
        ..MobilParams::default()
    };
    let v = verdict(&egoist, &a, false);
    close(v.incentive_mps2, gain);
    assert!(v.change);
}

#[test]
fn the_threshold_is_strict() {
    // The same lane beside as behind: incentive exactly 0, no change at Δa_th = 0 either.
    let me = car(0.0, 20.0, 25.0);
    let leader = car(40.0, 18.0, 25.0);
    let n = Neighbourhood {
        leader_now: Some(leader),
        leader_after: Some(leader),
        ..alone(me)
    };
    let a = change_accelerations(&IdmParams::default(), &n);
    let zero = MobilParams {
        threshold_mps2: 0.0,
        ..MobilParams::default()
    };
    let v = verdict(&zero, &a, false);
    assert_eq!(v.incentive_mps2, 0.0);
    assert!(v.safe && !v.change);
}

#[test]
fn leaving_an_ending_lane_gets_the_bias() {
    // Nothing to gain but the bias: 0 + 0.3 > 0.1 leaving a lane that ends, 0 otherwise.
    let me = car(0.0, 20.0, 25.0);
    let leader = car(40.0, 18.0, 25.0);
    let n = Neighbourhood {
        leader_now: Some(leader),
        leader_after: Some(leader),
        leaving_ending_lane: true,
        ..alone(me)
    };
    let v = decide(&IdmParams::default(), &MobilParams::default(), &n);
    close(v.incentive_mps2, 0.3);
    assert!(v.change);
    let v = decide(
        &IdmParams::default(),
        &MobilParams::default(),
        &Neighbourhood {
            leaving_ending_lane: false,
            ..n
        },
    );
    assert!(!v.change);
}

#[test]
fn a_lane_end_is_a_standing_obstacle_until_a_gap_opens() {
    // At its desired 15 m/s, 97.75 m from the end of its lane: the end brakes it at
    // 0.73·(127.89/97.75)² = 1.2496 m/s². Beside it a car at 15 m/s 35.5 m ahead: −0.3916.
    let me = car(0.0, 15.0, 15.0);
    let n = Neighbourhood {
        leader_now: Some(LaneDriver::lane_end(100.0)),
        leader_after: Some(car(40.0, 15.0, 15.0)),
        leaving_ending_lane: true,
        ..alone(me)
    };
    let a = change_accelerations(&IdmParams::default(), &n);
    close(a.me.0, -1.2495814384895658);
    close(a.me.1, -0.3915731005752827);
    let v = verdict(&MobilParams::default(), &a, true);
    close(v.incentive_mps2, 0.8580083379142831 + 0.3);
    assert!(v.change);
    // A car close behind the gap: no gap yet, so it stays and brakes for the end.
    let blocked = Neighbourhood {
        follower_after: Some(car(-6.0, 15.0, 15.0)),
        ..n
    };
    let v = decide(&IdmParams::default(), &MobilParams::default(), &blocked);
    assert!(!v.safe && !v.change);
}

#[test]
fn parameters_are_checked_by_name() {
    assert!(MobilParams::default().validate().is_ok());
    let bad = MobilParams {
        safe_decel_mps2: 0.0,
        ..MobilParams::default()
    };
    let message = bad.validate().unwrap_err().to_string();
    assert!(message.contains("mobil.safe_decel_mps2"), "{message}");
}
