//! A frame's RGB pixels as a GIF frame (palette + indices) that keeps the vehicles' colours
//! exact: a GIF holds at most 256 colours per frame, and the usual quantisation (NeuQuant)
//! moves every colour a little, so a vehicle's colour in the GIF would differ from the
//! recording's and the figures'.

use std::collections::HashMap;

/// At most this many colours of a frame are kept exactly when it has more than 256; the rest
/// of the palette (at least 128 entries) is NeuQuant's.
const MAX_EXACT: usize = 128;

/// The palette (RGB triplets) and one palette index per pixel of `rgb` (3 bytes per pixel).
///
/// A frame with at most 256 colours is stored exactly. Otherwise the colours of `keep` found in
/// the frame (the vehicles' colours, at most [`MAX_EXACT`]) get their own palette entries and
/// their pixels keep them; every other pixel takes its nearest colour in a NeuQuant palette of
/// the frame. Deterministic: the same pixels give the same bytes.
pub(super) fn index_frame(rgb: &[u8], keep: &[[u8; 3]]) -> (Vec<u8>, Vec<u8>) {
    let mut exact: HashMap<[u8; 3], u8> = HashMap::new();
    let mut palette: Vec<u8> = Vec::new();
    let mut indices = Vec::with_capacity(rgb.len() / 3);
    for p in rgb.chunks_exact(3) {
        let color = [p[0], p[1], p[2]];
        let next = exact.len();
        if next > 256 {
            break;
        }
        let index = *exact.entry(color).or_insert_with(|| {
            palette.extend_from_slice(&color);
            next.min(255) as u8
        });
        indices.push(index);
    }
    if exact.len() <= 256 {
        return (palette, indices);
    }
    // More than 256 colours: the kept ones exactly, NeuQuant for the rest.
    let present: std::collections::HashSet<[u8; 3]> = rgb
        .chunks_exact(3)
        .map(|p| [p[0], p[1], p[2]])
        .filter(|c| keep.contains(c))
        .collect();
    let mut reserved: Vec<[u8; 3]> = Vec::new();
    for c in keep {
        if present.contains(c) && !reserved.contains(c) && reserved.len() < MAX_EXACT {
            reserved.push(*c);
        }
    }
    let rgba: Vec<u8> = rgb
        .chunks_exact(3)
        .flat_map(|p| [p[0], p[1], p[2], 255])
        .collect();
    let quantizer = color_quant::NeuQuant::new(10, 256 - reserved.len(), &rgba);
    let mut palette: Vec<u8> = reserved.iter().flatten().copied().collect();
    palette.extend(quantizer.color_map_rgb());
    let offset = reserved.len();
    let indices = rgba
        .chunks_exact(4)
        .map(|p| match reserved.iter().position(|c| c[..] == p[..3]) {
            Some(k) => k as u8,
            None => (offset + quantizer.index_of(p)).min(255) as u8,
        })
        .collect();
    (palette, indices)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn decode(palette: &[u8], indices: &[u8]) -> Vec<[u8; 3]> {
        indices
            .iter()
            .map(|&i| {
                let i = 3 * usize::from(i);
                [palette[i], palette[i + 1], palette[i + 2]]
            })
            .collect()
    }

    #[test]
    fn few_colours_are_stored_exactly() {
        let rgb = [10u8, 20, 30, 44, 160, 44, 10, 20, 30];
        let (palette, indices) = index_frame(&rgb, &[]);
        assert_eq!(palette.len(), 6);
        assert_eq!(indices, [0, 1, 0]);
        assert_eq!(
            decode(&palette, &indices),
            [[10, 20, 30], [44, 160, 44], [10, 20, 30]]
        );
    }

    #[test]
    fn kept_colours_stay_exact_among_many() {
        // A smooth gradient of 4096 colours plus two vehicle colours near it.
        let vehicles = [[44u8, 160, 44], [31, 119, 180]];
        let mut rgb = Vec::new();
        for r in 0..64u8 {
            for g in 0..64u8 {
                rgb.extend_from_slice(&[4 * r, 4 * g, 100]);
            }
        }
        for _ in 0..50 {
            for v in vehicles {
                rgb.extend_from_slice(&v);
            }
        }
        let (palette, indices) = index_frame(&rgb, &vehicles);
        assert!(palette.len() <= 256 * 3);
        let decoded = decode(&palette, &indices);
        let n = 64 * 64;
        for (k, pixel) in decoded[n..].iter().enumerate() {
            assert_eq!(*pixel, vehicles[k % 2]);
        }
        // The gradient is approximated, not replaced by a vehicle's colour.
        assert!(
            decoded[..n].iter().all(|p| !vehicles.contains(p)),
            "a gradient pixel took a vehicle's colour"
        );
    }
}
