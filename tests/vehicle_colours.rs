//! One colour per vehicle across the outputs: the Rerun recording's box colour of each vehicle,
//! the GIF's pixels where that vehicle is, and the square before the caption of its PNG
//! figure (`compare --plots`) are the same RGB.

mod common;

use std::collections::BTreeMap;
use std::io::BufReader;
use std::path::Path;

use common::{merge_sim, scratch, stderr};
use mergesim::animation::{FrameGeometry, GifParams, GifView};
use mergesim::scenarios::scenario::Scenario;
use re_log_encoding::DecoderApp;
use rerun::log::{Chunk, LogMsg};

/// The colour of each vehicle's box in the recording, by its label.
fn recording_colours(path: &Path) -> BTreeMap<String, [u8; 3]> {
    let file = std::fs::File::open(path).unwrap();
    let mut colours = BTreeMap::new();
    for msg in DecoderApp::decode_lazy(BufReader::new(file)) {
        let LogMsg::ArrowMsg(_, arrow_msg) = msg.unwrap() else {
            continue;
        };
        let chunk = Chunk::from_arrow_msg(&arrow_msg).unwrap();
        if chunk.entity_path().to_string() != "/world/vehicles" {
            continue;
        }
        let colour_id = rerun::Boxes2D::descriptor_colors().component;
        let label_id = rerun::Boxes2D::descriptor_labels().component;
        let rows_c: Vec<Vec<rerun::components::Color>> = chunk
            .iter_component::<rerun::components::Color>(colour_id)
            .map(|r| r.to_vec())
            .collect();
        let rows_l: Vec<Vec<rerun::components::Text>> = chunk
            .iter_component::<rerun::components::Text>(label_id)
            .map(|r| r.to_vec())
            .collect();
        for (c, l) in rows_c.iter().zip(&rows_l) {
            for (color, label) in c.iter().zip(l) {
                let [r, g, b, _] = color.to_array();
                let previous = colours.insert(label.as_str().to_string(), [r, g, b]);
                assert!(
                    previous.is_none_or(|p| p == [r, g, b]),
                    "{} changed colour in the recording",
                    label.as_str()
                );
            }
        }
    }
    colours
}

/// The first frame of a GIF as RGBA and its width.
fn first_gif_frame(path: &Path) -> (u16, Vec<u8>) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let mut decoder = options
        .read_info(std::fs::File::open(path).unwrap())
        .unwrap();
    let w = decoder.width();
    let frame = decoder.read_next_frame().unwrap().unwrap().buffer.to_vec();
    (w, frame)
}

/// A PNG as RGB and its width.
fn png_pixels(path: &Path) -> (u32, Vec<u8>) {
    let decoder = png::Decoder::new(std::fs::File::open(path).unwrap());
    let mut reader = decoder.read_info().unwrap();
    let mut buffer = vec![0; reader.output_buffer_size()];
    let info = reader.next_frame(&mut buffer).unwrap();
    assert_eq!(info.color_type, png::ColorType::Rgb);
    buffer.truncate(info.buffer_size());
    (info.width, buffer)
}

/// (t, vehicle, x, y) of the `--csv` rows.
fn csv_rows(path: &Path) -> Vec<(f64, String, f64, f64)> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (t, v, x, y) = (col("t_s"), col("vehicle"), col("x_m"), col("y_m"));
    lines
        .map(|line| {
            let f: Vec<&str> = line.split(',').collect();
            (
                f[t].parse().unwrap(),
                f[v].to_string(),
                f[x].parse().unwrap(),
                f[y].parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn a_vehicle_has_the_same_colour_in_the_recording_the_gif_and_the_figures() {
    let dir = scratch("vehicle_colours");
    let (rrd, gif, csv, plots) = (
        dir.join("dense.rrd"),
        dir.join("dense.gif"),
        dir.join("dense.csv"),
        dir.join("plots"),
    );
    let p = |path: &Path| path.to_str().unwrap().to_string();
    let out = merge_sim(&[
        "run",
        "--scenario",
        "dense_merge",
        "--quiet",
        "--rrd",
        &p(&rrd),
        "--gif",
        &p(&gif),
        "--csv",
        &p(&csv),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = merge_sim(&[
        "compare",
        "--scenario",
        "dense_merge",
        "--planners",
        "pf-iso",
        "--plots",
        &p(&plots),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));

    let scenario = Scenario::load("dense_merge").unwrap();
    let recording = recording_colours(&rrd);
    assert_eq!(recording.len(), scenario.vehicles.len(), "{recording:?}");

    // The GIF's first frame (the whole road: six vehicles): the pixel at each vehicle's centre.
    let rows = csv_rows(&csv);
    let t0 = rows[0].0;
    let series: Vec<mergesim::sim::TimeSeriesRow> = rows
        .iter()
        .map(|(t, v, x, y)| mergesim::sim::TimeSeriesRow {
            t_s: *t,
            vehicle: v.clone(),
            x_m: *x,
            y_m: *y,
            yaw_rad: 0.0,
            yaw_rate_radps: 0.0,
            sideslip_rad: 0.0,
            speed_mps: 0.0,
            planned_speed_mps: 0.0,
            accel_long_mps2: 0.0,
            accel_lat_mps2: 0.0,
        })
        .collect();
    let params = GifParams {
        view: GifView::Road,
        ..GifParams::default()
    };
    let lanes = scenario
        .sim
        .road
        .lane_road()
        .unwrap_or_else(|e| panic!("{e}"));
    let geometry = FrameGeometry::whole_road(&lanes, &params, &series);
    let (w, frame) = first_gif_frame(&gif);
    for (_, name, x, y) in rows.iter().filter(|r| r.0 == t0) {
        let (px, py) = geometry.to_px(*x, *y);
        let i = 4 * (py as usize * usize::from(w) + px as usize);
        let in_gif = [frame[i], frame[i + 1], frame[i + 2]];
        assert_eq!(in_gif, recording[name], "{name}: GIF vs recording");
    }

    // Each vehicle's figure: the square before its caption.
    for spec in &scenario.vehicles {
        let (width, pixels) = png_pixels(&plots.join(format!("states_{}.png", spec.name)));
        let i = 3 * (14 * width as usize + 16);
        let in_png = [pixels[i], pixels[i + 1], pixels[i + 2]];
        assert_eq!(
            in_png, recording[&spec.name],
            "{}: PNG vs recording",
            spec.name
        );
        // And the paths figure draws the vehicle in that colour.
        let (width, paths) = png_pixels(&plots.join("paths.png"));
        assert_eq!(width, 1400);
        assert!(
            paths.chunks(3).any(|c| c == in_png),
            "{}: its colour is not in paths.png",
            spec.name
        );
    }
    // The colours are the one palette's, by id, and distinct.
    for (id, spec) in scenario.vehicles.iter().enumerate() {
        assert_eq!(
            recording[&spec.name],
            mergesim::sim::recording::vehicle_color(id as u32)
        );
    }
    std::fs::remove_dir_all(&dir).ok();
}
