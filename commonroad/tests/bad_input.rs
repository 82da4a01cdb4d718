//! Bad CommonRoad input: each refusal names the file, the line and the element.

use std::fmt::Write as _;
use std::path::Path;

use mergesim_commonroad::{ErrorKind, MAX_LANELETS, MAX_OBSTACLES, read_file, read_str};

const FILE: &str = "bad.xml";

fn lanelet(id: u32, y: f64, extra: &str) -> String {
    format!(
        "  <lanelet id=\"{id}\">\n    <leftBound><point><x>0</x><y>{}</y></point><point><x>50</x><y>{}</y></point></leftBound>\n    <rightBound><point><x>0</x><y>{y}</y></point><point><x>50</x><y>{y}</y></point></rightBound>\n{extra}  </lanelet>\n",
        y + 3.5,
        y + 3.5
    )
}

fn doc(version: &str, body: &str) -> String {
    format!(
        "<?xml version=\"1.0\"?>\n<commonRoad commonRoadVersion=\"{version}\" timeStepSize=\"0.1\" benchmarkID=\"T\">\n{body}</commonRoad>\n"
    )
}

fn read(text: &str) -> mergesim_commonroad::CommonRoadError {
    read_str(Path::new(FILE), text).expect_err("refused")
}

#[test]
fn a_good_file_is_read() {
    let s = read_str(Path::new(FILE), &doc("2020a", &lanelet(1, 0.0, ""))).unwrap();
    assert_eq!(s.lanelets.len(), 1);
}

#[test]
fn malformed_xml_names_the_line() {
    let text = doc("2020a", &lanelet(1, 0.0, "    <successor ref=\"2\">\n"));
    let e = read(&text);
    assert!(matches!(e.kind, ErrorKind::Xml(_)), "{e}");
    assert!(e.line.is_some(), "{e}");
    assert!(e.to_string().starts_with("bad.xml:"), "{e}");
}

#[test]
fn unknown_lanelet_reference_names_line_and_lanelet() {
    let text = doc("2020a", &lanelet(1, 0.0, "    <successor ref=\"7\"/>\n"));
    let e = read(&text);
    assert!(
        matches!(e.kind, ErrorKind::UnknownLanelet { target: 7, .. }),
        "{e}"
    );
    assert_eq!(e.line, Some(6));
    assert_eq!(e.element.as_deref(), Some("lanelet 1"));
    let msg = e.to_string();
    assert!(
        msg.contains("bad.xml:6: lanelet 1:") && msg.contains("lanelet 7"),
        "{msg}"
    );
}

#[test]
fn bounds_with_different_point_counts_are_refused() {
    let l = lanelet(4, 0.0, "").replace(
        "</leftBound>",
        "<point><x>60</x><y>3.5</y></point></leftBound>",
    );
    let text = doc("2020a", &format!("{}{l}", lanelet(3, 10.0, "")));
    let e = read(&text);
    assert!(
        matches!(e.kind, ErrorKind::BoundPointCounts { left: 3, right: 2 }),
        "{e}"
    );
    assert_eq!(e.line, Some(7));
    assert_eq!(e.element.as_deref(), Some("lanelet 4"));
}

#[test]
fn unsupported_version_is_refused() {
    let e = read(&doc("2017a", &lanelet(1, 0.0, "")));
    assert!(
        matches!(e.kind, ErrorKind::UnsupportedVersion { .. }),
        "{e}"
    );
    assert_eq!(e.line, Some(2));
    assert!(e.to_string().contains("2017a"));
}

#[test]
fn too_many_lanelets_are_refused() {
    let mut body = String::new();
    for i in 0..=MAX_LANELETS as u32 {
        body.push_str(&lanelet(i, 4.0 * f64::from(i), ""));
    }
    let e = read(&doc("2020a", &body));
    assert!(
        matches!(e.kind, ErrorKind::TooMany { what: "lanelets", count, max } if count == MAX_LANELETS + 1 && max == MAX_LANELETS),
        "{e}"
    );
}

#[test]
fn too_many_obstacles_are_refused() {
    let mut body = lanelet(1, 0.0, "");
    for i in 0..=MAX_OBSTACLES {
        let _ = writeln!(
            body,
            "  <staticObstacle id=\"{}\"><type>parkedVehicle</type><shape><rectangle><length>4</length><width>2</width></rectangle></shape><initialState><position><point><x>1</x><y>1</y></point></position><orientation><exact>0</exact></orientation><time><exact>0</exact></time></initialState></staticObstacle>",
            100 + i
        );
    }
    let e = read(&doc("2020a", &body));
    assert!(
        matches!(e.kind, ErrorKind::TooMany { what: "obstacles", count, .. } if count == MAX_OBSTACLES + 1),
        "{e}"
    );
}

#[test]
fn a_bad_number_names_the_obstacle() {
    let body = format!(
        "{}  <dynamicObstacle id=\"9\">\n    <type>car</type>\n    <shape><rectangle><length>4</length><width>x</width></rectangle></shape>\n  </dynamicObstacle>\n",
        lanelet(1, 0.0, "")
    );
    let e = read(&doc("2020a", &body));
    assert!(matches!(e.kind, ErrorKind::BadNumber { .. }), "{e}");
    assert_eq!(e.element.as_deref(), Some("dynamicObstacle 9"));
    assert_eq!(e.line, Some(9));
}

#[test]
fn a_missing_file_names_the_file() {
    let e = read_file(Path::new("/nonexistent/none.xml")).expect_err("refused");
    assert!(matches!(e.kind, ErrorKind::Io(_)));
    assert!(e.to_string().contains("/nonexistent/none.xml"));
}
