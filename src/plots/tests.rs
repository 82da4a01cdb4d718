//! Tests of the PNG figures: layout, legends, captions and colours.

use super::*;

fn caption() -> RunCaption {
    RunCaption {
        scenario: "urgent_merge".into(),
        params: "mergesim".into(),
        seed: None,
        commit: "0123456789ab".into(),
        recorded_traffic: None,
    }
}

fn merge_lanes() -> LaneRoad {
    mergesim_types::MergeRoad::default()
        .lane_road()
        .unwrap_or_else(|e| panic!("{e}"))
}

/// Draws a figure into memory: its RGB pixels and what `draw` returned.
fn render_in_memory<T>(
    size: (u32, u32),
    draw: impl FnOnce(&DrawingArea<BitMapBackend<'_>, Shift>) -> Result<T, String>,
) -> (Vec<u8>, T) {
    ensure_font().unwrap_or_else(|e| panic!("{e}"));
    let mut buffer = vec![0u8; 3 * size.0 as usize * size.1 as usize];
    let layout = {
        let area = BitMapBackend::with_buffer(&mut buffer, size).into_drawing_area();
        area.fill(&WHITE).unwrap_or_else(|e| panic!("{e}"));
        let layout = draw(&area).unwrap_or_else(|e| panic!("{e}"));
        area.present().unwrap_or_else(|e| panic!("{e}"));
        layout
    };
    (buffer, layout)
}

/// The colour of pixel (x, y) of an RGB buffer `width` wide.
fn pixel(buffer: &[u8], width: u32, (x, y): (i32, i32)) -> Option<[u8; 3]> {
    if x < 0 || y < 0 || x >= width as i32 {
        return None;
    }
    let i = 3 * (y as usize * width as usize + x as usize);
    buffer.get(i..i + 3).map(|p| [p[0], p[1], p[2]])
}

/// Checks that the legends of `layouts` stay out of their plotting areas and that every
/// point of `points` (data coordinates) with t ≤ 2 s is drawn, visible, in `color`: its
/// pixel or one next to it has exactly that colour (a legend over it would hide or blend it).
fn assert_first_seconds_visible(
    buffer: &[u8],
    width: u32,
    layouts: &[PanelLayout],
    points: &dyn Fn(usize) -> Vec<(f64, f64, f64)>,
    color: RGBColor,
) {
    let rgb = [color.0, color.1, color.2];
    for (k, layout) in layouts.iter().enumerate() {
        assert!(
            !layout.legend_px.intersects(&layout.plot_px),
            "panel {k}: legend {:?} inside the plotting area {:?}",
            layout.legend_px,
            layout.plot_px
        );
        let early: Vec<(f64, f64, f64)> = points(k).into_iter().filter(|p| p.0 <= 2.0).collect();
        assert!(early.len() >= 20, "panel {k}: too few points to test");
        for &(t, x, y) in &early {
            let (px, py) = layout.to_px(x, y);
            assert!(
                !layout.legend_px.contains((px, py)),
                "panel {k}: the legend covers the point at t = {t} s"
            );
            let seen = (-1..=1)
                .any(|dx| (-1..=1).any(|dy| pixel(buffer, width, (px + dx, py + dy)) == Some(rgb)));
            assert!(
                seen,
                "panel {k}: the point at t = {t} s ({px}, {py}) is hidden: {:?}",
                pixel(buffer, width, (px, py))
            );
        }
    }
}

/// A vehicle whose every motion state sweeps its whole range in the first 2 s (where a
/// legend in a corner of the chart sat), then settles: 20 s at 20 Hz.
fn sweeping_rows() -> Vec<TimeSeriesRow> {
    (1..=400)
        .map(|k| {
            let t = 0.05 * f64::from(k);
            let v = if t <= 2.0 {
                (2.0 * std::f64::consts::PI * 2.5 * t).sin()
            } else {
                0.3 * (0.5 * t).sin()
            };
            TimeSeriesRow {
                t_s: t,
                vehicle: "ego".into(),
                x_m: 15.0 * t,
                y_m: 3.5 + 3.0 * v,
                yaw_rad: v,
                yaw_rate_radps: v,
                sideslip_rad: v,
                speed_mps: 15.0 + 5.0 * v,
                planned_speed_mps: 15.0,
                accel_long_mps2: 0.0,
                accel_lat_mps2: 0.0,
            }
        })
        .collect()
}

#[test]
fn legends_cover_no_data_in_the_first_two_seconds() {
    let rows = sweeping_rows();
    let series = [PlannerSeries {
        planner: "pf-iso",
        rows: &rows,
        collisions: &[],
    }];
    let size = FigureSize::default();
    // Fig. 4: the four panels, one line (the planner's colour).
    let dims = states_size(size);
    let (buffer, layouts) = render_in_memory(dims, |area| {
        draw_states_figure(area, &series, "ego", 0, &caption())
    });
    assert_eq!(layouts.len(), 4);
    type Getter = fn(&TimeSeriesRow) -> f64;
    let getters: [Getter; 4] = [
        |r| r.sideslip_rad,
        |r| r.yaw_rad,
        |r| r.yaw_rate_radps,
        |r| r.speed_mps,
    ];
    let points = |k: usize| -> Vec<(f64, f64, f64)> {
        rows.iter().map(|r| (r.t_s, r.t_s, getters[k](r))).collect()
    };
    assert_first_seconds_visible(
        &buffer,
        dims.0,
        &layouts,
        &points,
        planner_color("pf-iso", 0),
    );
    // Fig. 3: the path, weaving across the road in the first 2 s (the vehicle's colour).
    let dims = paths_size(size, 1);
    let (buffer, layouts) = render_in_memory(dims, |area| {
        draw_paths_figure(
            area,
            &merge_lanes(),
            false,
            &series,
            &["ego".to_string()],
            &caption(),
        )
    });
    let points =
        |_: usize| -> Vec<(f64, f64, f64)> { rows.iter().map(|r| (r.t_s, r.x_m, r.y_m)).collect() };
    assert_first_seconds_visible(&buffer, dims.0, &layouts, &points, vehicle_rgb(0));
}

#[test]
fn figures_open_with_the_caption_band() {
    let rows = sweeping_rows();
    let series = [PlannerSeries {
        planner: "pf-iso",
        rows: &rows,
        collisions: &[],
    }];
    let dims = states_size(FigureSize::default());
    // Vehicle id 3: the square before the caption is its colour.
    let (buffer, layouts) = render_in_memory(dims, |area| {
        draw_states_figure(area, &series, "ego", 3, &caption())
    });
    let band_dark = (0..CAPTION_PX as i32)
        .flat_map(|y| (0..dims.0 as i32).map(move |x| (x, y)))
        .filter(|&p| pixel(&buffer, dims.0, p).is_some_and(|c| c.iter().all(|&v| v < 120)))
        .count();
    assert!(
        band_dark > 200,
        "no caption text drawn ({band_dark} dark pixels)"
    );
    let swatch = vehicle_rgb(3);
    assert_eq!(
        pixel(&buffer, dims.0, (16, 14)),
        Some([swatch.0, swatch.1, swatch.2])
    );
    // The charts start below the band.
    assert!(layouts.iter().all(|l| l.plot_px.y0 >= CAPTION_PX as i32));
}

fn row(t_s: f64, vehicle: &str, x_m: f64, y_m: f64) -> TimeSeriesRow {
    TimeSeriesRow {
        t_s,
        vehicle: vehicle.into(),
        x_m,
        y_m,
        yaw_rad: 0.01 * t_s,
        yaw_rate_radps: 0.01,
        sideslip_rad: 0.0,
        speed_mps: 15.0,
        planned_speed_mps: 15.0,
        accel_long_mps2: 0.0,
        accel_lat_mps2: 0.0,
    }
}

#[test]
fn padded_range_contains_the_values_and_widens_a_constant() {
    let r = padded_range([1.0, 3.0].into_iter(), 0.1, 0.5);
    assert!(r.start < 1.0 && r.end > 3.0);
    assert!((r.start - 0.8).abs() < 1e-12 && (r.end - 3.2).abs() < 1e-12);
    let flat = padded_range([2.0, 2.0].into_iter(), 0.0, 0.5);
    assert!((flat.end - flat.start - 0.5).abs() < 1e-12);
    let empty = padded_range([f64::NAN].into_iter(), 0.0, 1.0);
    assert_eq!(empty, 0.0..1.0);
}

#[test]
fn earlier_planners_are_wider_and_vehicles_have_distinct_colours() {
    let widths: Vec<u32> = (0..4).map(|i| planner_stroke(i, 4)).collect();
    assert!(widths.windows(2).all(|w| w[0] > w[1]), "{widths:?}");
    let colors: Vec<RGBColor> = (0..4).map(vehicle_rgb).collect();
    for i in 0..4 {
        for j in 0..i {
            assert_ne!(colors[i], colors[j]);
        }
    }
}

#[test]
fn vehicle_names_keep_first_appearance_order() {
    let rows = [
        row(0.0, "ego", 0.0, 1.75),
        row(0.0, "obstacle", 35.0, 5.25),
        row(0.1, "ego", 2.0, 1.75),
    ];
    assert_eq!(vehicle_names(&rows), ["ego", "obstacle"]);
}

#[test]
fn csv_has_one_line_per_row_with_the_planner_first() {
    let rows = [row(0.0, "ego", 0.0, 1.75), row(0.0, "obstacle", 35.0, 5.25)];
    let text = comparison_csv(&[
        PlannerSeries {
            planner: "pf-cs",
            rows: &rows,
            collisions: &[],
        },
        PlannerSeries {
            planner: "pf-iso",
            rows: &rows[..1],
            collisions: &[],
        },
    ]);
    let lines: Vec<&str> = text.lines().collect();
    assert_eq!(lines.len(), 4);
    assert_eq!(lines[0], format!("planner,{}", TimeSeriesRow::CSV_HEADER));
    assert!(lines[1].starts_with("pf-cs,0.0000,ego,"));
    assert!(lines[3].starts_with("pf-iso,0.0000,ego,"));
    let columns = lines[0].split(',').count();
    assert!(lines.iter().all(|l| l.split(',').count() == columns));
}

#[test]
fn figures_are_png_files_and_no_temporary_file_is_left() {
    let dir = std::env::temp_dir().join(format!("mergesim_plots_{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let rows: Vec<TimeSeriesRow> = (0..50)
        .flat_map(|i| {
            let t = 0.1 * i as f64;
            [
                row(t, "ego", 20.0 * t, 1.75),
                row(t, "obstacle", 35.0 + 15.0 * t, 5.25),
            ]
        })
        .collect();
    let crash = [CollisionEvent {
        t_s: 2.0,
        id_a: 0,
        id_b: 1,
        t_contact_estimate_s: None,
        relative_speed_mps: 5.0,
        caused_by_replay: false,
    }];
    assert_eq!(collision_marks(&rows, &crash).len(), 2);
    let series = [
        PlannerSeries {
            planner: "pf-cs",
            rows: &rows,
            collisions: &crash,
        },
        PlannerSeries {
            planner: "pf-iso",
            rows: &rows,
            collisions: &[],
        },
    ];
    let size = FigureSize {
        width_px: 400,
        panel_height_px: 120,
    };
    let written = write_comparison(&dir, &merge_lanes(), false, &series, size, &caption()).unwrap();
    let names: Vec<String> = written
        .iter()
        .map(|p| p.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(
        names,
        [
            "paths.png",
            "states_ego.png",
            "states_obstacle.png",
            "time_series.csv"
        ]
    );
    for path in &written[..3] {
        let bytes = std::fs::read(path).unwrap();
        // PNG signature and the IHDR width/height (big endian) of the figure.
        assert_eq!(&bytes[..8], b"\x89PNG\r\n\x1a\n");
        let width = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
        assert_eq!(width, 400);
    }
    let height = |name: &str| {
        let bytes = std::fs::read(dir.join(name)).unwrap();
        u32::from_be_bytes(bytes[20..24].try_into().unwrap())
    };
    assert_eq!(height("paths.png"), CAPTION_PX + 2 * 120);
    assert_eq!(height("states_obstacle.png"), CAPTION_PX + 4 * 120);
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().starts_with('.'))
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn empty_series_is_an_error_not_a_panic() {
    let err = write_comparison(
        Path::new("."),
        &merge_lanes(),
        false,
        &[],
        FigureSize::default(),
        &caption(),
    );
    assert!(matches!(err, Err(PlotError::Empty(_))));
}

#[test]
fn a_missing_folder_is_rejected() {
    assert!(check_plot_dir(Path::new("/definitely/not/here"), &[]).is_err());
    // A missing folder whose parent exists is created later.
    assert!(check_plot_dir(&std::env::temp_dir().join("mergesim_new_plots"), &[]).is_ok());
    assert!(check_plot_dir(Path::new(""), &[]).is_err());
    let dir = std::env::temp_dir().join(format!("mergesim_plot_files_{}", std::process::id()));
    std::fs::create_dir_all(dir.join("states_ego.png")).unwrap();
    assert!(check_plot_dir(&dir, &["obstacle"]).is_ok());
    let err = check_plot_dir(&dir, &["ego"]).unwrap_err();
    assert!(
        err.contains("states_ego.png") && err.contains("directory"),
        "{err}"
    );
    assert_eq!(states_png("../a"), "states__a.png");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Fig. 3 on the 300 m-radius curved merge road: the outer edges are drawn (black) along the
/// curve, every vertex of them inside the plotting area on a black pixel, and the path of a
/// vehicle driving round it in its colour.
#[test]
fn the_paths_figure_draws_a_curved_road() {
    let spec =
        mergesim_types::lanes::curved_merge_spec(&mergesim_types::MergeRoad::default(), 300.0)
            .unwrap_or_else(|e| panic!("{e}"));
    let lanes = LaneRoad::new(&spec).unwrap_or_else(|e| panic!("{e}"));
    let lane = lanes
        .lane(mergesim_types::lanes::THROUGH_LANE_ID)
        .unwrap_or_else(|| panic!("no through lane"));
    let rows: Vec<TimeSeriesRow> = (0..=300)
        .map(|k| {
            let t = 0.1 * f64::from(k);
            let [x_m, y_m] = lane.point(10.0 + 10.0 * t, 0.0);
            TimeSeriesRow {
                t_s: t,
                vehicle: "ego".into(),
                x_m,
                y_m,
                yaw_rad: 0.0,
                yaw_rate_radps: 0.0,
                sideslip_rad: 0.0,
                speed_mps: 10.0,
                planned_speed_mps: 10.0,
                accel_long_mps2: 0.0,
                accel_lat_mps2: 0.0,
            }
        })
        .collect();
    let series = [PlannerSeries {
        planner: "pf-iso",
        rows: &rows,
        collisions: &[],
    }];
    let size = FigureSize {
        width_px: 900,
        panel_height_px: 700,
    };
    let dims = paths_size(size, 1);
    let (buffer, layouts) = render_in_memory(dims, |area| {
        draw_paths_figure(
            area,
            &lanes,
            true,
            &series,
            &["ego".to_string()],
            &caption(),
        )
    });
    let layout = &layouts[0];
    let black = [0u8, 0, 0];
    let (mut inside, mut on_edge) = (0usize, 0usize);
    for p in sim::road_drawing::RoadDrawing::new(&lanes)
        .outer_edges
        .iter()
        .flatten()
    {
        let px = layout.to_px(p[0], p[1]);
        if !layout.plot_px.contains(px) {
            continue;
        }
        inside += 1;
        let seen = (-1..=1).any(|dx| {
            (-1..=1).any(|dy| pixel(&buffer, dims.0, (px.0 + dx, px.1 + dy)) == Some(black))
        });
        on_edge += usize::from(seen);
    }
    assert!(inside > 300, "{inside}");
    assert!(
        on_edge as f64 >= 0.97 * inside as f64,
        "{on_edge} of {inside}"
    );
    let points =
        |_: usize| -> Vec<(f64, f64, f64)> { rows.iter().map(|r| (r.t_s, r.x_m, r.y_m)).collect() };
    assert_first_seconds_visible(&buffer, dims.0, &layouts, &points, vehicle_rgb(0));
}
