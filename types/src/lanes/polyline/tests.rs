//! Tests of the centreline polyline.
use super::*;

#[test]
fn cleaning_keeps_the_last_vertex_and_drops_near_duplicates() {
    let raw = [
        [0.0, 0.0],
        [0.0, 0.0],
        [1.0, 0.0],
        [1.001, 0.0005],
        [2.0, 0.0],
        [2.02, 0.0],
    ];
    assert_eq!(clean_indices(&raw, 0.05), vec![0, 2, 5]);
}

#[test]
fn straight_line_projects_exactly() {
    let c = Centreline::new(LaneId(1), &[[0.0, 0.0], [10.0, 0.0]], 0.05, 0.0).unwrap();
    let fp = c.project([3.0, 2.0]);
    assert_eq!((fp.s_m, fp.d_m), (3.0, 2.0));
    let fp = c.project([-3.0, -2.0]);
    assert_eq!((fp.s_m, fp.d_m), (-3.0, -2.0));
    let fp = c.project([13.0, 1.0]);
    assert_eq!((fp.s_m, fp.d_m), (13.0, 1.0));
    assert_eq!(c.curvature_1pm(5.0), 0.0);
}

#[test]
fn window_mean_reproduces_linear_data() {
    let s = [0.0, 1.0, 2.5, 4.0, 7.0];
    let v: Vec<f64> = s.iter().map(|x| 2.0 * x - 1.0).collect();
    let m = window_mean(&s, &v, 1.2);
    for (a, b) in m.iter().zip(&v) {
        assert!((a - b).abs() < 1e-12, "{a} vs {b}");
    }
}
