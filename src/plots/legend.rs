//! The legend of a panel and the figure's caption band. The legend is drawn in a column right
//! of the chart, outside its plotting area, so it never covers data (inside the chart it hid
//! the first seconds of every curve).

use plotters::coord::Shift;
use plotters::prelude::*;

use super::font;

/// A rectangle of the figure in pixels: `x0..x1` × `y0..y1` (ends excluded).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PixelBox {
    /// Left (px).
    pub x0: i32,
    /// Top (px).
    pub y0: i32,
    /// Right, excluded (px).
    pub x1: i32,
    /// Bottom, excluded (px).
    pub y1: i32,
}

impl PixelBox {
    /// Whether pixel (x, y) lies inside.
    pub fn contains(&self, (x, y): (i32, i32)) -> bool {
        (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y)
    }

    /// Whether the two boxes share a pixel.
    pub fn intersects(&self, other: &PixelBox) -> bool {
        self.x0 < other.x1 && other.x0 < self.x1 && self.y0 < other.y1 && other.y0 < self.y1
    }
}

/// How an entry is drawn in the legend.
#[derive(Clone, Copy, Debug)]
pub(super) enum Mark {
    /// A short solid line.
    Line(ShapeStyle),
    /// A short dashed line.
    Dashed(ShapeStyle),
    /// A red cross (collisions).
    Cross,
}

/// One line of a legend.
#[derive(Clone, Debug)]
pub(super) struct LegendEntry {
    /// Its text.
    pub(super) label: String,
    /// Its sample.
    pub(super) mark: Mark,
}

/// Height of one legend line (px).
const ROW_PX: i32 = 20;
/// Length of the line sample (px).
const SWATCH_PX: i32 = 26;
/// Padding inside the legend box and between it and the chart (px).
const PAD_PX: i32 = 8;
/// Font size of the legend (px).
const LEGEND_FONT: u32 = 14;

/// Height of the caption band at the top of a figure (px).
pub(crate) const CAPTION_PX: u32 = 28;

/// Splits `panel` into the chart's area (left) and a legend column (right) wide enough for
/// the labels of `entries`.
pub(super) fn split_for_legend<'a>(
    panel: &DrawingArea<BitMapBackend<'a>, Shift>,
    entries: &[LegendEntry],
) -> (
    DrawingArea<BitMapBackend<'a>, Shift>,
    DrawingArea<BitMapBackend<'a>, Shift>,
) {
    let text_px = entries
        .iter()
        .map(|e| {
            panel
                .estimate_text_size(&e.label, &font(LEGEND_FONT))
                .map_or(8 * e.label.len() as i32, |(w, _)| w as i32)
        })
        .chain(std::iter::once(60))
        .max()
        .unwrap_or(60);
    let column = text_px + SWATCH_PX + 4 * PAD_PX;
    let (w, _) = panel.dim_in_pixel();
    panel.split_horizontally((w as i32 - column).max(1))
}

/// Draws `entries` top-down in `column` from `top_px` (relative to it), in a framed box; the
/// entries that do not fit are summarised as "+N more". Returns the box (figure pixels).
pub(super) fn draw_legend(
    column: &DrawingArea<BitMapBackend<'_>, Shift>,
    entries: &[LegendEntry],
    top_px: i32,
) -> Result<PixelBox, String> {
    let e = |err: &dyn std::fmt::Display| err.to_string();
    let (w, h) = column.dim_in_pixel();
    let (w, h) = (w as i32, h as i32);
    let fit = ((h - top_px - 2 * PAD_PX) / ROW_PX).max(1) as usize;
    let (shown, more) = if entries.len() > fit {
        (&entries[..fit - 1], entries.len() - (fit - 1))
    } else {
        (entries, 0)
    };
    let rows = shown.len() as i32 + i32::from(more > 0);
    let (x0, y0) = (PAD_PX, top_px);
    let (x1, y1) = (w - PAD_PX, top_px + rows * ROW_PX + PAD_PX);
    column
        .draw(&Rectangle::new([(x0, y0), (x1, y1)], WHITE.filled()))
        .map_err(|x| e(&x))?;
    column
        .draw(&Rectangle::new([(x0, y0), (x1, y1)], BLACK.stroke_width(1)))
        .map_err(|x| e(&x))?;
    for (k, entry) in shown.iter().enumerate() {
        let y = y0 + PAD_PX / 2 + k as i32 * ROW_PX + ROW_PX / 2;
        let (sx0, sx1) = (x0 + PAD_PX, x0 + PAD_PX + SWATCH_PX);
        match entry.mark {
            Mark::Line(style) => column
                .draw(&PathElement::new([(sx0, y), (sx1, y)], style))
                .map_err(|x| e(&x))?,
            Mark::Dashed(style) => {
                for (a, b) in [(0, 8), (12, 20), (24, SWATCH_PX)] {
                    column
                        .draw(&PathElement::new([(sx0 + a, y), (sx0 + b, y)], style))
                        .map_err(|x| e(&x))?;
                }
            }
            Mark::Cross => column
                .draw(&Cross::new(((sx0 + sx1) / 2, y), 5, RED.stroke_width(2)))
                .map_err(|x| e(&x))?,
        }
        column
            .draw(&Text::new(
                entry.label.clone(),
                (sx1 + PAD_PX, y - 8),
                font(LEGEND_FONT),
            ))
            .map_err(|x| e(&x))?;
    }
    if more > 0 {
        let y = y0 + PAD_PX / 2 + shown.len() as i32 * ROW_PX + ROW_PX / 2;
        column
            .draw(&Text::new(
                format!("+{more} more"),
                (x0 + PAD_PX, y - 8),
                font(LEGEND_FONT),
            ))
            .map_err(|x| e(&x))?;
    }
    let (bx, by) = column.get_base_pixel();
    Ok(PixelBox {
        x0: bx + x0,
        y0: by + y0,
        x1: bx + x1 + 1,
        y1: by + y1 + 1,
    })
}

/// Draws `text` in a band of [`CAPTION_PX`] at the top of `area`, after a square in `swatch`
/// if given; returns the rest of the area, below the band.
pub(crate) fn draw_caption<'a>(
    area: &DrawingArea<BitMapBackend<'a>, Shift>,
    text: &str,
    swatch: Option<RGBColor>,
) -> Result<DrawingArea<BitMapBackend<'a>, Shift>, String> {
    let (band, rest) = area.split_vertically(CAPTION_PX);
    let mut x = 10;
    if let Some(color) = swatch {
        band.draw(&Rectangle::new([(x, 7), (x + 14, 21)], color.filled()))
            .map_err(|e| e.to_string())?;
        x += 22;
    }
    band.draw(&Text::new(
        text.to_string(),
        (x, 6),
        font(15).color(&RGBColor(60, 60, 60)),
    ))
    .map_err(|e| e.to_string())?;
    Ok(rest)
}
