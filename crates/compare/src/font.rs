//! A tiny 5×7 bitmap font for heat-map labels (digits, a few letters and signs), drawn at an
//! integer scale. Embedded so the colour bar needs no font file or font crate.

/// Glyph cell width and height in font pixels; glyphs advance by `GLYPH_W + 1`.
pub const GLYPH_W: u32 = 5;
pub const GLYPH_H: u32 = 7;
const ADVANCE: u32 = GLYPH_W + 1;

/// Rows top to bottom; bit 4 is the leftmost column.
fn glyph(c: char) -> Option<[u8; 7]> {
    Some(match c {
        '0' => [0b01110, 0b10001, 0b10011, 0b10101, 0b11001, 0b10001, 0b01110],
        '1' => [0b00100, 0b01100, 0b00100, 0b00100, 0b00100, 0b00100, 0b01110],
        '2' => [0b01110, 0b10001, 0b00001, 0b00010, 0b00100, 0b01000, 0b11111],
        '3' => [0b11111, 0b00010, 0b00100, 0b00010, 0b00001, 0b10001, 0b01110],
        '4' => [0b00010, 0b00110, 0b01010, 0b10010, 0b11111, 0b00010, 0b00010],
        '5' => [0b11111, 0b10000, 0b11110, 0b00001, 0b00001, 0b10001, 0b01110],
        '6' => [0b00110, 0b01000, 0b10000, 0b11110, 0b10001, 0b10001, 0b01110],
        '7' => [0b11111, 0b00001, 0b00010, 0b00100, 0b01000, 0b01000, 0b01000],
        '8' => [0b01110, 0b10001, 0b10001, 0b01110, 0b10001, 0b10001, 0b01110],
        '9' => [0b01110, 0b10001, 0b10001, 0b01111, 0b00001, 0b00010, 0b01100],
        '.' => [0, 0, 0, 0, 0, 0b01100, 0b01100],
        '-' => [0, 0, 0, 0b11111, 0, 0, 0],
        '+' => [0, 0b00100, 0b00100, 0b11111, 0b00100, 0b00100, 0],
        '>' => [0b10000, 0b01000, 0b00100, 0b00010, 0b00100, 0b01000, 0b10000],
        '=' => [0, 0, 0b11111, 0, 0b11111, 0, 0],
        'E' => [0b11111, 0b10000, 0b10000, 0b11110, 0b10000, 0b10000, 0b11111],
        'e' => [0, 0, 0b01110, 0b10001, 0b11111, 0b10000, 0b01110],
        'd' => [0b00001, 0b00001, 0b01101, 0b10011, 0b10001, 0b10011, 0b01101],
        'a' => [0, 0, 0b01110, 0b00001, 0b01111, 0b10001, 0b01111],
        'm' => [0, 0, 0b11010, 0b10101, 0b10101, 0b10101, 0b10101],
        'x' => [0, 0, 0b10001, 0b01010, 0b00100, 0b01010, 0b10001],
        'Δ' => [0b00100, 0b00100, 0b01010, 0b01010, 0b10001, 0b10001, 0b11111],
        ' ' => [0; 7],
        _ => return None,
    })
}

/// Whether `c` has a glyph (others draw as a hollow box, so a gap in the font is visible).
pub fn has_glyph(c: char) -> bool {
    glyph(c).is_some()
}

/// Width in pixels of `text` at `scale`.
pub fn text_width(text: &str, scale: u32) -> u32 {
    let n = text.chars().count() as u32;
    if n == 0 { 0 } else { (n * ADVANCE - 1) * scale }
}

/// Height in pixels of one line at `scale`.
pub fn text_height(scale: u32) -> u32 {
    GLYPH_H * scale
}

/// Draws `text` with its top-left corner at (`x`, `y`) into a row-major RGB8 buffer of
/// `width` columns; pixels outside the buffer are clipped.
pub fn draw_text(pixels: &mut [[u8; 3]], width: u32, x: i64, y: i64, text: &str, scale: u32, rgb: [u8; 3]) {
    const BOX: [u8; 7] = [0b11111, 0b10001, 0b10001, 0b10001, 0b10001, 0b10001, 0b11111];
    let height = (pixels.len() / width.max(1) as usize) as i64;
    let s = i64::from(scale);
    for (i, c) in text.chars().enumerate() {
        let rows = glyph(c).unwrap_or(BOX);
        let gx = x + i as i64 * i64::from(ADVANCE) * s;
        for (r, bits) in rows.iter().enumerate() {
            for col in 0..GLYPH_W {
                if bits >> (GLYPH_W - 1 - col) & 1 == 0 {
                    continue;
                }
                for dy in 0..s {
                    for dx in 0..s {
                        let px = gx + i64::from(col) * s + dx;
                        let py = y + r as i64 * s + dy;
                        if (0..i64::from(width)).contains(&px) && (0..height).contains(&py) {
                            pixels[(py * i64::from(width) + px) as usize] = rgb;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn render(text: &str, scale: u32) -> (u32, Vec<[u8; 3]>) {
        let w = text_width(text, scale) + 2;
        let h = text_height(scale) + 2;
        let mut px = vec![[255u8; 3]; (w * h) as usize];
        draw_text(&mut px, w, 1, 1, text, scale, [0; 3]);
        (w, px)
    }

    #[test]
    fn digits_are_distinct_and_fit_the_cell() {
        let all: Vec<[u8; 7]> = "0123456789".chars().map(|c| glyph(c).unwrap()).collect();
        for (i, a) in all.iter().enumerate() {
            assert!(a.iter().all(|r| *r < 32), "digit {i} wider than 5");
            for b in &all[i + 1..] {
                assert_ne!(a, b);
            }
        }
    }

    #[test]
    fn scale_multiplies_ink() {
        let ink = |px: &[[u8; 3]]| px.iter().filter(|p| p[0] == 0).count();
        let bits: u32 = glyph('8').unwrap().iter().map(|r| r.count_ones()).sum();
        assert_eq!(ink(&render("8", 1).1), bits as usize);
        assert_eq!(ink(&render("8", 3).1), 9 * bits as usize);
        // Two glyphs side by side: one blank column between them at scale 1.
        assert_eq!(text_width("88", 1), 11);
        assert_eq!(ink(&render("88", 1).1), 2 * bits as usize);
    }

    #[test]
    fn unknown_characters_stay_visible_and_clipping_is_safe() {
        assert!(!has_glyph('?'));
        let (_, px) = render("?", 1);
        assert!(px.iter().any(|p| p[0] == 0));
        let mut small = vec![[255u8; 3]; 9];
        draw_text(&mut small, 3, -2, -3, "0123", 4, [0; 3]);
    }
}
