//! `merge_sim run --gif`, `--gif-view` and `--follow` as a user runs them: the animation's
//! frames and size, the vehicles in it, and bad input refused with exit code 2 before any work.

mod common;

use std::path::Path;

use common::{merge_sim, scratch, stderr};

/// Frames, width, height and delays (centiseconds) of a GIF; the first frame as RGBA.
fn decode_gif(path: &Path) -> (usize, u16, u16, Vec<u16>, Vec<u8>) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(path).unwrap();
    let mut decoder = options.read_info(file).unwrap();
    let (w, h) = (decoder.width(), decoder.height());
    let mut frames = 0;
    let mut delays = Vec::new();
    let mut first = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        if frames == 0 {
            first = frame.buffer.to_vec();
        }
        frames += 1;
        delays.push(frame.delay);
    }
    (frames, w, h, delays, first)
}

/// Every frame of a GIF as RGBA, and its size.
fn decode_frames(path: &Path) -> (u16, u16, Vec<Vec<u8>>) {
    let mut options = gif::DecodeOptions::new();
    options.set_color_output(gif::ColorOutput::RGBA);
    let file = std::fs::File::open(path).unwrap();
    let mut decoder = options.read_info(file).unwrap();
    let (w, h) = (decoder.width(), decoder.height());
    let mut frames = Vec::new();
    while let Some(frame) = decoder.read_next_frame().unwrap() {
        assert_eq!((frame.width, frame.height), (w, h), "a partial frame");
        frames.push(frame.buffer.to_vec());
    }
    (w, h, frames)
}

/// Which of the first `n` vehicles' colours (by id) a frame shows.
fn vehicles_shown(frame: &[u8], n: u32) -> Vec<bool> {
    (0..n)
        .map(|id| {
            let rgb = mergesim::sim::recording::vehicle_color(id);
            frame.chunks(4).any(|p| p[..3] == rgb)
        })
        .collect()
}

#[test]
fn the_road_view_is_the_default_beyond_two_vehicles_and_shows_every_one_in_every_frame() {
    let dir = scratch("gif_road_view");
    let road = dir.join("road.gif");
    let follow = dir.join("follow.gif");
    // dense_merge: six vehicles, 30 s.
    for (path, extra) in [(&road, &[][..]), (&follow, &["--gif-view", "follow"][..])] {
        let mut args = vec![
            "run",
            "--scenario",
            "dense_merge",
            "--no-rrd",
            "--quiet",
            "--gif",
            path.to_str().unwrap(),
        ];
        args.extend_from_slice(extra);
        let out = merge_sim(&args);
        assert!(out.status.success(), "{extra:?}: {}", stderr(&out));
    }
    let (w, h, frames) = decode_frames(&road);
    assert_eq!(frames.len(), 300);
    assert_eq!(w, 800);
    for (k, frame) in frames.iter().enumerate() {
        let shown = vehicles_shown(frame, 6);
        assert!(
            shown.iter().all(|&s| s),
            "road view, frame {k}: vehicles shown {shown:?}"
        );
    }
    // `follow` keeps the window of before: its size, and cars leave it.
    let (fw, fh, follow_frames) = decode_frames(&follow);
    assert_eq!((fw, fh), (800, 132));
    assert_ne!(h, fh);
    assert_eq!(follow_frames.len(), 300);
    let incomplete = follow_frames
        .iter()
        .filter(|f| !vehicles_shown(f, 6).iter().all(|&s| s))
        .count();
    assert!(
        incomplete > 0,
        "the follow window showed every car in every frame"
    );
    // The followed vehicle (the scenario's first, upper1) is in every frame of it.
    assert!(follow_frames.iter().all(|f| vehicles_shown(f, 1)[0]));
}

#[test]
fn a_bad_gif_view_is_refused_before_the_run() {
    let dir = scratch("gif_bad_view");
    let gif = dir.join("x.gif");
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--gif",
        gif.to_str().unwrap(),
        "--gif-view",
        "sideways",
    ]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--gif-view"), "{}", stderr(&out));
    assert!(!gif.exists());
    // Without --gif it is a usage error too.
    let out = merge_sim(&["run", "--no-rrd", "--gif-view", "road"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn gif_has_one_frame_per_tenth_of_a_second_and_shows_the_vehicles() {
    let dir = scratch("gif_default");
    let gif = dir.join("urgent.gif");
    let out = merge_sim(&["run", "--no-rrd", "--gif", gif.to_str().unwrap()]);
    assert!(out.status.success(), "{}", stderr(&out));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("gif: ") && stdout.contains("250 frames"),
        "{stdout}"
    );
    let (frames, w, h, delays, first) = decode_gif(&gif);
    // 25 s logged at 20 Hz from t = 0.05 s, one frame per 0.1 s.
    assert_eq!(frames, 250);
    assert_eq!(w, 800);
    // 22 px header + (7 m road + 2 × 2 m margins) × 10 px/m.
    assert_eq!(h, 132);
    assert!(delays.iter().all(|&d| d == 10), "{delays:?}");
    // The ego's green and the obstacle's blue (the recording's palette) are in the first frame.
    let has = |rgb: [u8; 3]| first.chunks(4).any(|p| p[..3] == rgb);
    assert!(has([44, 160, 44]), "no ego in the first frame");
    assert!(has([31, 119, 180]), "no obstacle in the first frame");
    // Nothing else left in the folder (the temporary file was renamed).
    let names: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(names, ["urgent.gif"]);
}

#[test]
fn gif_options_change_rate_and_size() {
    let dir = scratch("gif_options");
    let gif = dir.join("small.gif");
    let out = merge_sim(&[
        "run",
        "--no-rrd",
        "--quiet",
        "--follow",
        "obstacle",
        "--gif",
        gif.to_str().unwrap(),
        "--gif-fps",
        "5",
        "--gif-width",
        "400",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(out.stdout.is_empty(), "--quiet prints nothing");
    let (frames, w, _, delays, _) = decode_gif(&gif);
    assert_eq!(frames, 125);
    assert_eq!(w, 400);
    assert!(delays.iter().all(|&d| d == 20));
}

/// `--lane-ids` writes the lanes' ids into the GIF (the frames differ from those without it);
/// on `compare` it needs `--plots` (refused with exit 2 otherwise).
#[test]
fn lane_ids_are_drawn_on_request() {
    let dir = scratch("gif_lane_ids");
    let gifs = [dir.join("plain.gif"), dir.join("ids.gif")];
    for (gif, extra) in gifs.iter().zip([None, Some("--lane-ids")]) {
        let mut args = vec![
            "run",
            "--no-rrd",
            "--quiet",
            "--gif",
            gif.to_str().unwrap(),
            "--gif-fps",
            "1",
            "--gif-view",
            "road",
        ];
        args.extend(extra);
        let out = merge_sim(&args);
        assert!(out.status.success(), "{}", stderr(&out));
    }
    let (frames, w, h, _, _) = decode_gif(&gifs[0]);
    assert_eq!(decode_gif(&gifs[1]).0, frames);
    assert_eq!((decode_gif(&gifs[1]).1, decode_gif(&gifs[1]).2), (w, h));
    let bytes = |p: &std::path::Path| std::fs::read(p).unwrap();
    assert_ne!(bytes(&gifs[0]), bytes(&gifs[1]), "--lane-ids drew nothing");
    let out = merge_sim(&["compare", "--lane-ids"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(stderr(&out).contains("--plots"), "{}", stderr(&out));
}

/// The GIF draws the scenario's own road: `curved_merge`'s 300 m-radius curve makes the whole-
/// road view taller than wide (the straight `[sim.road]` it also carries is a thin strip; the
/// CLI drew that one until it asked the scenario for its lanes).
#[test]
fn the_gif_draws_the_scenarios_road_of_lanes() {
    let dir = scratch("gif_curved");
    let gif = dir.join("curved.gif");
    let out = merge_sim(&[
        "run",
        "--scenario",
        "curved_merge",
        "--no-rrd",
        "--quiet",
        "--gif",
        gif.to_str().unwrap(),
        "--gif-fps",
        "1",
        "--gif-view",
        "road",
        "--gif-width",
        "300",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let (_, w, h, _, _) = decode_gif(&gif);
    assert!(h > w, "{w} x {h} px: the curve is not drawn");
}

#[test]
fn bad_follow_and_gif_options_are_refused_before_the_run() {
    let dir = scratch("gif_bad");
    let gif = dir.join("x.gif");
    let cases: [(&[&str], &str); 4] = [
        (&["--follow", "nobody"], "--follow"),
        (&["--gif-fps", "0"], "fps"),
        (&["--gif-width", "20"], "width"),
        (&["--gif", "/nonexistent/dir/x.gif"], "does not exist"),
    ];
    for (extra, needle) in cases {
        let mut args = vec!["run", "--no-rrd"];
        if !extra.contains(&"--gif") {
            args.extend(["--gif", gif.to_str().unwrap()]);
        }
        args.extend_from_slice(extra);
        let started = std::time::Instant::now();
        let out = merge_sim(&args);
        assert_eq!(out.status.code(), Some(2), "{extra:?}: {}", stderr(&out));
        assert!(stderr(&out).contains(needle), "{extra:?}: {}", stderr(&out));
        assert!(!gif.exists(), "{extra:?} wrote the gif");
        // Refused before the simulation (which takes ~0.3 s) and the drawing (~3 s).
        assert!(started.elapsed().as_secs_f64() < 2.0, "{extra:?} was slow");
    }
    // --gif-fps without --gif is a usage error too.
    let out = merge_sim(&["run", "--no-rrd", "--gif-fps", "5"]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn view_without_the_rerun_viewer_on_path_is_refused_before_the_run() {
    let dir = scratch("view_no_viewer");
    let empty = dir.join("empty_path");
    std::fs::create_dir_all(&empty).unwrap();
    let rrd = dir.join("run.rrd");
    let args = [
        "run",
        "--duration",
        "1",
        "--view",
        "--rrd",
        rrd.to_str().unwrap(),
    ];
    let out = common::merge_sim_env(&args, &[("PATH", empty.to_str().unwrap())]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--view: the Rerun viewer `rerun` is not on PATH"),
        "{}",
        stderr(&out)
    );
    assert!(!rrd.exists(), "refused before the run: no recording");

    // A `rerun` on PATH (here a stand-in that exits at once) lets the run go ahead.
    let bin = dir.join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    let viewer = bin.join("rerun");
    std::fs::write(&viewer, "#!/bin/sh\nexit 0\n").unwrap();
    {
        use std::os::unix::fs::PermissionsExt as _;
        std::fs::set_permissions(&viewer, std::fs::Permissions::from_mode(0o755)).unwrap();
    }
    let out = common::merge_sim_env(&args, &[("PATH", bin.to_str().unwrap())]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(rrd.exists());
}
