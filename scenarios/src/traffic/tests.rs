use super::*;

/// The main stream of the built-in `on_ramp_flow`: 1,400–2,000 veh/h over two lanes, 25 m/s,
/// a 600 m (24 s) window, h₀ = 1 s.
fn main_stream() -> TrafficStream {
    TrafficStream {
        flow_vph: FlowRange {
            uniform: [1400.0, 2000.0],
        },
        lanes: vec![StartLane::Id(LaneId(1)), StartLane::Id(LaneId(2))],
        rear_x_m: 20.0,
        front_x_m: 620.0,
        speed_mps: 25.0,
        min_headway_s: 1.0,
        ..TrafficStream::default()
    }
}

fn traffic_of(stream: TrafficStream) -> Traffic {
    Traffic::from([("main".to_string(), stream)])
}

use mergesim_types::lanes::LaneId;

/// The x of each lane's vehicles, front first, by lane label.
fn by_lane(vehicles: &[VehicleSpec]) -> BTreeMap<String, Vec<f64>> {
    let mut lanes: BTreeMap<String, Vec<f64>> = BTreeMap::new();
    for v in vehicles {
        lanes.entry(lane_label(v.lane)).or_default().push(v.x_m);
    }
    lanes
}

#[test]
fn a_seed_gives_the_same_vehicles_and_other_seeds_other_counts() {
    let traffic = traffic_of(main_stream());
    let a = generate(&traffic, TrafficInstance::Seed(42));
    assert_eq!(a, generate(&traffic, TrafficInstance::Seed(42)));
    assert!(!a.is_empty());
    // The count varies with the seed (it is a random count, not a fixed one).
    let counts: std::collections::BTreeSet<usize> = (0..50)
        .map(|seed| generate(&traffic, TrafficInstance::Seed(seed)).len())
        .collect();
    assert!(counts.len() > 3, "{counts:?}");
    // Names: stream, lane as written, index from the front; unique.
    assert_eq!(a[0].name, "main_1_00");
    let names: std::collections::BTreeSet<&str> = a.iter().map(|v| v.name.as_str()).collect();
    assert_eq!(names.len(), a.len());
    // Every vehicle drives at the stream's speed, with its driver.
    assert!(a.iter().all(|v| v.speed_mps == 25.0
        && v.target_speed_mps == 25.0
        && v.driver == Driver::planner("pf-iso")));
}

#[test]
fn adding_a_stream_changes_no_other_streams_draws() {
    let one = traffic_of(main_stream());
    let mut two = one.clone();
    two.insert(
        "ramp".into(),
        TrafficStream {
            lanes: vec![StartLane::Id(LaneId(4))],
            ..main_stream()
        },
    );
    let seed = 9;
    let main_only = generate(&one, TrafficInstance::Seed(seed));
    let both = generate(&two, TrafficInstance::Seed(seed));
    assert_eq!(&both[..main_only.len()], &main_only[..]);
    assert!(both.len() > main_only.len());
}

#[test]
fn headways_respect_the_minimum_and_cars_do_not_overlap() {
    let stream = main_stream();
    let traffic = traffic_of(stream.clone());
    let length_m = vehicles::VehicleParams::preset("bmw_320i")
        .unwrap()
        .length_m;
    let min_spacing_m = stream.speed_mps * stream.min_headway_s;
    assert!(min_spacing_m > length_m);
    let mut smallest_m = f64::INFINITY;
    for seed in 0..500 {
        for (lane, xs) in by_lane(&generate(&traffic, TrafficInstance::Seed(seed))) {
            assert!(
                xs.iter().all(|x| (20.0..=620.0).contains(x)),
                "{lane}: {xs:?}"
            );
            for pair in xs.windows(2) {
                let spacing_m = pair[0] - pair[1];
                smallest_m = smallest_m.min(spacing_m);
                assert!(
                    spacing_m >= min_spacing_m * (1.0 - 1e-12),
                    "seed {seed} lane {lane}: spacing {spacing_m} m"
                );
                assert!(spacing_m > length_m);
            }
        }
    }
    // The minimum is reached often enough to be approached (the exponential part near 0).
    assert!(smallest_m < min_spacing_m + 1.0, "{smallest_m}");
}

#[test]
fn the_mean_generated_flow_is_the_drawn_flow() {
    // Per instance and lane, the count N in the window of duration T against its expectation
    // T/μ (equation (4), μ from the flow that instance drew): r = N·μ/T has mean exactly 1.
    // Over n = 2 × 4000 lane windows the mean of r lies within 4 standard errors of 1
    // (s/√n, s the sample standard deviation: a two-sided 6·10⁻⁵ false-alarm rate by the CLT).
    // The bound is below the bias an ordinary renewal process (first gap a full headway) would
    // give, (σ² − μ²)/(2μ²) vehicles per lane, so placing the front car wrongly fails the test.
    let stream = main_stream();
    let traffic = traffic_of(stream.clone());
    let window_s = stream.window_s();
    let mut ratios = Vec::new();
    let mut drawn = Vec::new();
    for seed in 0..4000 {
        let flow = stream.drawn_flow_vph("main", seed);
        drawn.push(flow);
        let mu = stream.mean_headway_s(flow);
        for xs in by_lane(&generate(&traffic, TrafficInstance::Seed(seed))).values() {
            ratios.push(xs.len() as f64 * mu / window_s);
        }
        // A lane without any vehicle is counted too (N = 0).
        let lanes = by_lane(&generate(&traffic, TrafficInstance::Seed(seed))).len();
        ratios.extend(std::iter::repeat_n(0.0, 2 - lanes));
    }
    let n = ratios.len() as f64;
    let mean = ratios.iter().sum::<f64>() / n;
    let sd = (ratios.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let bound = 4.0 * sd / n.sqrt();
    assert!((mean - 1.0).abs() < bound, "mean {mean}, bound {bound}");
    // The bias of the ordinary renewal process at the centre flow, relative to T/μ.
    let mu = stream.mean_headway_s(1700.0);
    let tail = mu - stream.min_headway_s;
    let ordinary_bias = (tail * tail - mu * mu) / (2.0 * mu * mu) / (window_s / mu);
    assert!(bound < ordinary_bias.abs(), "{bound} vs {ordinary_bias}");
    // The flows themselves are uniform on [1400, 2000]: mean 1700, sd 600/√12.
    let mean_flow = drawn.iter().sum::<f64>() / drawn.len() as f64;
    let flow_se = 600.0 / 12f64.sqrt() / (drawn.len() as f64).sqrt();
    assert!((mean_flow - 1700.0).abs() < 4.0 * flow_se, "{mean_flow}");
    assert!(drawn.iter().all(|q| (1400.0..=2000.0).contains(q)));
}

#[test]
fn the_nominal_instance_has_centre_flows_and_mean_headways() {
    let stream = main_stream();
    let vehicles = generate(&traffic_of(stream.clone()), TrafficInstance::Nominal);
    let mu = stream.mean_headway_s(1700.0);
    // x_k = front − v·μ·(k + ½) while ≥ rear: ⌊T/μ + ½⌋ per lane.
    let per_lane = (stream.window_s() / mu + 0.5).floor() as usize;
    let lanes = by_lane(&vehicles);
    assert_eq!(lanes.len(), 2);
    for xs in lanes.values() {
        assert_eq!(xs.len(), per_lane);
        assert!((xs[0] - (620.0 - 0.5 * 25.0 * mu)).abs() < 1e-9);
        for pair in xs.windows(2) {
            assert!((pair[0] - pair[1] - 25.0 * mu).abs() < 1e-9);
        }
    }
}

#[test]
fn the_densest_instance_bounds_every_count_and_spans_the_window() {
    let stream = main_stream();
    let traffic = traffic_of(stream.clone());
    let densest = generate(&traffic, TrafficInstance::Densest);
    let per_lane = ((620.0 - 20.0) / 25.0_f64).floor() as usize + 1;
    assert_eq!(densest.len(), 2 * per_lane);
    for xs in by_lane(&densest).values() {
        assert_eq!(xs[0], 620.0);
        assert_eq!(*xs.last().unwrap(), 20.0);
    }
    for seed in 0..300 {
        assert!(generate(&traffic, TrafficInstance::Seed(seed)).len() <= densest.len());
    }
}

#[test]
fn bad_values_name_their_key() {
    let cases: [(&str, TrafficStream); 6] = [
        (
            "flow_vph",
            TrafficStream {
                flow_vph: FlowRange {
                    uniform: [2000.0, 1400.0],
                },
                ..main_stream()
            },
        ),
        (
            "lanes",
            TrafficStream {
                lanes: vec![],
                ..main_stream()
            },
        ),
        (
            "speed_mps",
            TrafficStream {
                speed_mps: 0.0,
                ..main_stream()
            },
        ),
        (
            "min_headway_s",
            TrafficStream {
                min_headway_s: f64::NAN,
                ..main_stream()
            },
        ),
        (
            "front_x_m",
            TrafficStream {
                front_x_m: 10.0,
                ..main_stream()
            },
        ),
        // 2,000 veh/h over two lanes is a mean headway of 3.6 s, below h₀ = 4 s.
        (
            "flow_vph",
            TrafficStream {
                min_headway_s: 4.0,
                ..main_stream()
            },
        ),
    ];
    assert!(main_stream().validate("main").is_ok());
    for (key, stream) in cases {
        let issue = stream.validate("main").unwrap_err();
        assert_eq!(issue.key, key, "{}", issue.message);
    }
    assert!(main_stream().validate("bad name").is_err());
}

#[test]
fn stream_of_finds_the_longest_matching_stream_name() {
    let mut traffic = traffic_of(main_stream());
    traffic.insert("main_2".into(), main_stream());
    assert_eq!(stream_of(&traffic, "main_1_00"), Some("main"));
    assert_eq!(stream_of(&traffic, "main_2_upper_00"), Some("main_2"));
    assert_eq!(stream_of(&traffic, "ego"), None);
}
