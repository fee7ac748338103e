//! Minimal raster figures written as PNG: panels with axes, ticks, labels,
//! points, lines, grey-level maps and a legend. Self-contained (a 5×7 bitmap
//! font, text shown in capitals) so that scenes need no system fonts.

use std::path::Path;

/// An RGB colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

pub const BLACK: Rgb = Rgb(0, 0, 0);
pub const WHITE: Rgb = Rgb(255, 255, 255);
pub const GREY: Rgb = Rgb(150, 150, 150);
pub const RED: Rgb = Rgb(214, 39, 40);
pub const BLUE: Rgb = Rgb(31, 119, 180);

/// A categorical palette for orbits.
pub fn palette(i: usize) -> Rgb {
    const P: [Rgb; 10] = [
        Rgb(31, 119, 180),
        Rgb(255, 127, 14),
        Rgb(44, 160, 44),
        Rgb(214, 39, 40),
        Rgb(148, 103, 189),
        Rgb(140, 86, 75),
        Rgb(227, 119, 194),
        Rgb(80, 80, 80),
        Rgb(188, 189, 34),
        Rgb(23, 190, 207),
    ];
    P[i % P.len()]
}

/// Column-major 5×7 glyphs for ' '..='Z', bit 0 at the top.
const FONT: [[u8; 5]; 59] = [
    [0x00, 0x00, 0x00, 0x00, 0x00],
    [0x00, 0x00, 0x5F, 0x00, 0x00],
    [0x00, 0x07, 0x00, 0x07, 0x00],
    [0x14, 0x7F, 0x14, 0x7F, 0x14],
    [0x24, 0x2A, 0x7F, 0x2A, 0x12],
    [0x23, 0x13, 0x08, 0x64, 0x62],
    [0x36, 0x49, 0x55, 0x22, 0x50],
    [0x00, 0x05, 0x03, 0x00, 0x00],
    [0x00, 0x1C, 0x22, 0x41, 0x00],
    [0x00, 0x41, 0x22, 0x1C, 0x00],
    [0x08, 0x2A, 0x1C, 0x2A, 0x08],
    [0x08, 0x08, 0x3E, 0x08, 0x08],
    [0x00, 0x50, 0x30, 0x00, 0x00],
    [0x08, 0x08, 0x08, 0x08, 0x08],
    [0x00, 0x60, 0x60, 0x00, 0x00],
    [0x20, 0x10, 0x08, 0x04, 0x02],
    [0x3E, 0x51, 0x49, 0x45, 0x3E],
    [0x00, 0x42, 0x7F, 0x40, 0x00],
    [0x42, 0x61, 0x51, 0x49, 0x46],
    [0x21, 0x41, 0x45, 0x4B, 0x31],
    [0x18, 0x14, 0x12, 0x7F, 0x10],
    [0x27, 0x45, 0x45, 0x45, 0x39],
    [0x3C, 0x4A, 0x49, 0x49, 0x30],
    [0x01, 0x71, 0x09, 0x05, 0x03],
    [0x36, 0x49, 0x49, 0x49, 0x36],
    [0x06, 0x49, 0x49, 0x29, 0x1E],
    [0x00, 0x36, 0x36, 0x00, 0x00],
    [0x00, 0x56, 0x36, 0x00, 0x00],
    [0x00, 0x08, 0x14, 0x22, 0x41],
    [0x14, 0x14, 0x14, 0x14, 0x14],
    [0x41, 0x22, 0x14, 0x08, 0x00],
    [0x02, 0x01, 0x51, 0x09, 0x06],
    [0x32, 0x49, 0x79, 0x41, 0x3E],
    [0x7E, 0x11, 0x11, 0x11, 0x7E],
    [0x7F, 0x49, 0x49, 0x49, 0x36],
    [0x3E, 0x41, 0x41, 0x41, 0x22],
    [0x7F, 0x41, 0x41, 0x22, 0x1C],
    [0x7F, 0x49, 0x49, 0x49, 0x41],
    [0x7F, 0x09, 0x09, 0x01, 0x01],
    [0x3E, 0x41, 0x41, 0x51, 0x32],
    [0x7F, 0x08, 0x08, 0x08, 0x7F],
    [0x00, 0x41, 0x7F, 0x41, 0x00],
    [0x20, 0x40, 0x41, 0x3F, 0x01],
    [0x7F, 0x08, 0x14, 0x22, 0x41],
    [0x7F, 0x40, 0x40, 0x40, 0x40],
    [0x7F, 0x02, 0x04, 0x02, 0x7F],
    [0x7F, 0x04, 0x08, 0x10, 0x7F],
    [0x3E, 0x41, 0x41, 0x41, 0x3E],
    [0x7F, 0x09, 0x09, 0x09, 0x06],
    [0x3E, 0x41, 0x51, 0x21, 0x5E],
    [0x7F, 0x09, 0x19, 0x29, 0x46],
    [0x46, 0x49, 0x49, 0x49, 0x31],
    [0x01, 0x01, 0x7F, 0x01, 0x01],
    [0x3F, 0x40, 0x40, 0x40, 0x3F],
    [0x1F, 0x20, 0x40, 0x20, 0x1F],
    [0x7F, 0x20, 0x18, 0x20, 0x7F],
    [0x63, 0x14, 0x08, 0x14, 0x63],
    [0x03, 0x04, 0x78, 0x04, 0x03],
    [0x61, 0x51, 0x49, 0x45, 0x43],
];

/// An RGB raster image.
pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pixels: Vec<Rgb>,
}

impl Canvas {
    pub fn new(width: usize, height: usize) -> Canvas {
        Canvas {
            width,
            height,
            pixels: vec![WHITE; width * height],
        }
    }

    pub fn set(&mut self, x: i64, y: i64, c: Rgb) {
        if x >= 0 && y >= 0 && (x as usize) < self.width && (y as usize) < self.height {
            self.pixels[y as usize * self.width + x as usize] = c;
        }
    }

    pub fn fill_rect(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, c: Rgb) {
        for y in y0.min(y1)..=y0.max(y1) {
            for x in x0.min(x1)..=x0.max(x1) {
                self.set(x, y, c);
            }
        }
    }

    pub fn line(&mut self, (x0, y0): (i64, i64), (x1, y1): (i64, i64), c: Rgb) {
        let (dx, dy) = ((x1 - x0).abs(), -(y1 - y0).abs());
        let (sx, sy) = (if x0 < x1 { 1 } else { -1 }, if y0 < y1 { 1 } else { -1 });
        let (mut x, mut y, mut err) = (x0, y0, dx + dy);
        for _ in 0..=(dx - dy).min(100_000) {
            self.set(x, y, c);
            if x == x1 && y == y1 {
                break;
            }
            let e2 = 2 * err;
            if e2 >= dy {
                err += dy;
                x += sx;
            }
            if e2 <= dx {
                err += dx;
                y += sy;
            }
        }
    }

    /// Text in capitals with its top-left corner at (x, y); returns the width in pixels.
    pub fn text(&mut self, x: i64, y: i64, text: &str, scale: i64, c: Rgb) -> i64 {
        let mut cx = x;
        for ch in text.chars() {
            let ch = match ch.to_ascii_uppercase() {
                '[' | '{' => '(',
                ']' | '}' => ')',
                '_' => '-',
                '|' => '!',
                ch => ch,
            };
            let index = if (' '..='Z').contains(&ch) {
                ch as usize - 0x20
            } else {
                '?' as usize - 0x20
            };
            for (col, bits) in FONT[index].iter().enumerate() {
                for row in 0..7 {
                    if bits & (1 << row) != 0 {
                        let (px, py) = (cx + col as i64 * scale, y + row * scale);
                        self.fill_rect(px, py, px + scale - 1, py + scale - 1, c);
                    }
                }
            }
            cx += 6 * scale;
        }
        cx - x
    }

    pub fn text_width(text: &str, scale: i64) -> i64 {
        text.chars().count() as i64 * 6 * scale
    }

    /// Writes the image as PNG, atomically (temporary file, then rename).
    pub fn save_png(&self, path: &Path) -> std::io::Result<()> {
        let mut bytes = Vec::new();
        {
            let mut encoder = png::Encoder::new(&mut bytes, self.width as u32, self.height as u32);
            encoder.set_color(png::ColorType::Rgb);
            encoder.set_depth(png::BitDepth::Eight);
            let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
            let data: Vec<u8> = self.pixels.iter().flat_map(|p| [p.0, p.1, p.2]).collect();
            writer
                .write_image_data(&data)
                .map_err(std::io::Error::other)?;
        }
        crate::scene::write_atomic(path, &bytes)
    }
}

/// "Nice" tick positions covering [lo, hi].
pub fn ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    let span = (hi - lo).abs().max(1e-300);
    let raw = span / target.max(1) as f64;
    let magnitude = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * magnitude)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * magnitude);
    let first = (lo.min(hi) / step).ceil() as i64;
    let last = (lo.max(hi) / step).floor() as i64;
    (first..=last).map(|k| k as f64 * step).collect()
}

fn tick_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) {
        format!("{v:.0e}")
    } else {
        let s = format!("{v:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// One panel: a data rectangle mapped onto a pixel rectangle of a canvas.
#[derive(Clone, Copy, Debug)]
pub struct Panel {
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    /// Pixel box of the data area: left, top, width, height.
    pub left: i64,
    pub top: i64,
    pub width: i64,
    pub height: i64,
    pub log_x: bool,
    pub log_y: bool,
}

impl Panel {
    fn tx(&self, v: f64) -> f64 {
        if self.log_x {
            v.log10()
        } else {
            v
        }
    }
    fn ty(&self, v: f64) -> f64 {
        if self.log_y {
            v.log10()
        } else {
            v
        }
    }
    /// Pixel of a data point (may lie outside the box).
    pub fn pixel(&self, x: f64, y: f64) -> (i64, i64) {
        let (x0, x1) = (self.tx(self.x_range.0), self.tx(self.x_range.1));
        let (y0, y1) = (self.ty(self.y_range.0), self.ty(self.y_range.1));
        let px = self.left as f64 + (self.tx(x) - x0) / (x1 - x0) * (self.width - 1) as f64;
        let py = self.top as f64 + (y1 - self.ty(y)) / (y1 - y0) * (self.height - 1) as f64;
        (px.round() as i64, py.round() as i64)
    }
    fn inside(&self, (px, py): (i64, i64)) -> bool {
        px >= self.left
            && px < self.left + self.width
            && py >= self.top
            && py < self.top + self.height
    }
}

/// A figure of one or more panels in a grid.
pub struct Figure {
    pub canvas: Canvas,
    panels: Vec<Panel>,
}

pub struct PanelSpec<'a> {
    pub title: &'a str,
    pub x_label: &'a str,
    pub y_label: &'a str,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub log_x: bool,
    pub log_y: bool,
}

impl<'a> PanelSpec<'a> {
    pub fn new(
        title: &'a str,
        x_label: &'a str,
        y_label: &'a str,
        x_range: (f64, f64),
        y_range: (f64, f64),
    ) -> Self {
        PanelSpec {
            title,
            x_label,
            y_label,
            x_range,
            y_range,
            log_x: false,
            log_y: false,
        }
    }
    pub fn log_x(mut self) -> Self {
        self.log_x = true;
        self
    }
    pub fn log_log(mut self) -> Self {
        self.log_x = true;
        self.log_y = true;
        self
    }
}

const MARGIN_LEFT: i64 = 70;
const MARGIN_BOTTOM: i64 = 45;
const MARGIN_TOP: i64 = 30;
const MARGIN_RIGHT: i64 = 20;

impl Figure {
    /// A grid of `columns` × `rows` panels, each `panel_w` × `panel_h` pixels overall.
    pub fn grid(
        columns: usize,
        rows: usize,
        panel_w: usize,
        panel_h: usize,
        specs: &[PanelSpec],
    ) -> Figure {
        let mut canvas = Canvas::new(columns * panel_w, rows * panel_h);
        let mut panels = Vec::new();
        for (k, spec) in specs.iter().enumerate() {
            let (col, row) = ((k % columns) as i64, (k / columns) as i64);
            let (ox, oy) = (col * panel_w as i64, row * panel_h as i64);
            let panel = Panel {
                x_range: spec.x_range,
                y_range: spec.y_range,
                left: ox + MARGIN_LEFT,
                top: oy + MARGIN_TOP,
                width: panel_w as i64 - MARGIN_LEFT - MARGIN_RIGHT,
                height: panel_h as i64 - MARGIN_TOP - MARGIN_BOTTOM,
                log_x: spec.log_x,
                log_y: spec.log_y,
            };
            draw_frame(&mut canvas, &panel, spec);
            panels.push(panel);
        }
        Figure { canvas, panels }
    }

    pub fn single(width: usize, height: usize, spec: PanelSpec) -> Figure {
        Figure::grid(1, 1, width, height, &[spec])
    }

    pub fn panel(&self, k: usize) -> Panel {
        self.panels[k]
    }

    /// Dots at data points (1 pixel, or a small square for `size` > 1).
    pub fn points(
        &mut self,
        k: usize,
        points: impl IntoIterator<Item = (f64, f64)>,
        color: Rgb,
        size: i64,
    ) {
        let panel = self.panels[k];
        for (x, y) in points {
            if !x.is_finite() || !y.is_finite() {
                continue;
            }
            let p = panel.pixel(x, y);
            if panel.inside(p) {
                if size <= 1 {
                    self.canvas.set(p.0, p.1, color);
                } else {
                    let r = size / 2;
                    self.canvas
                        .fill_rect(p.0 - r, p.1 - r, p.0 + r, p.1 + r, color);
                }
            }
        }
    }

    /// A polyline; segments leaving the box are skipped.
    pub fn line(&mut self, k: usize, points: &[(f64, f64)], color: Rgb) {
        let panel = self.panels[k];
        for w in points.windows(2) {
            let (a, b) = (panel.pixel(w[0].0, w[0].1), panel.pixel(w[1].0, w[1].1));
            if panel.inside(a) && panel.inside(b) {
                self.canvas.line(a, b, color);
            }
        }
    }

    /// Fills the panel with a map: `value(x, y)` in [0, 1] → grey (1 = black).
    pub fn grey_map(&mut self, k: usize, columns: usize, rows: usize, values: &[f64]) {
        let panel = self.panels[k];
        for py in 0..panel.height {
            for px in 0..panel.width {
                let i = (px as usize * columns / panel.width as usize).min(columns - 1);
                let j = rows - 1 - (py as usize * rows / panel.height as usize).min(rows - 1);
                let v = values[j * columns + i];
                let g = if v.is_finite() {
                    (255.0 * (1.0 - v.clamp(0.0, 1.0))) as u8
                } else {
                    255
                };
                self.canvas
                    .set(panel.left + px, panel.top + py, Rgb(g, g, g));
            }
        }
        let frame = Rgb(0, 0, 0);
        let (l, t, r, b) = (
            panel.left - 1,
            panel.top - 1,
            panel.left + panel.width,
            panel.top + panel.height,
        );
        self.canvas.line((l, t), (r, t), frame);
        self.canvas.line((l, b), (r, b), frame);
        self.canvas.line((l, t), (l, b), frame);
        self.canvas.line((r, t), (r, b), frame);
    }

    /// Level sets of `f` with spacing `step` (and the level `special`, drawn in
    /// `special_color`): a pixel is marked where f crosses a level towards its neighbours.
    pub fn contours(
        &mut self,
        k: usize,
        f: &dyn Fn(f64, f64) -> f64,
        step: f64,
        color: Rgb,
        special: f64,
        special_color: Rgb,
    ) {
        let panel = self.panels[k];
        let (w, h) = (panel.width as usize, panel.height as usize);
        let (x0, x1, y0, y1) = (
            panel.x_range.0,
            panel.x_range.1,
            panel.y_range.0,
            panel.y_range.1,
        );
        let value = |i: usize, j: usize| {
            f(
                x0 + (x1 - x0) * i as f64 / (w - 1) as f64,
                y1 - (y1 - y0) * j as f64 / (h - 1) as f64,
            )
        };
        let grid: Vec<f64> = (0..h)
            .flat_map(|j| (0..w).map(move |i| (i, j)))
            .map(|(i, j)| value(i, j))
            .collect();
        for j in 0..h - 1 {
            for i in 0..w - 1 {
                let a = grid[j * w + i];
                for b in [grid[j * w + i + 1], grid[(j + 1) * w + i]] {
                    let (x, y) = (panel.left + i as i64, panel.top + j as i64);
                    if (a - special).signum() != (b - special).signum() {
                        self.canvas.fill_rect(x, y, x + 1, y + 1, special_color);
                    } else if (a / step).floor() != (b / step).floor() {
                        self.canvas.set(x, y, color);
                    }
                }
            }
        }
    }

    /// Legend lines in the panel's top-left corner, each with a colour swatch.
    pub fn legend(&mut self, k: usize, entries: &[(String, Rgb)]) {
        self.legend_at(k, entries, false);
    }

    /// Legend lines in the top-left or (`bottom`) bottom-left corner.
    pub fn legend_at(&mut self, k: usize, entries: &[(String, Rgb)], bottom: bool) {
        let panel = self.panels[k];
        let width = entries
            .iter()
            .map(|(s, _)| Canvas::text_width(s, 1))
            .max()
            .unwrap_or(0)
            + 22;
        let height = entries.len() as i64 * 10 + 6;
        let y = if bottom {
            panel.top + panel.height - height - 6
        } else {
            panel.top + 6
        };
        let x = panel.left + 6;
        self.canvas.fill_rect(x, y, x + width, y + height, WHITE);
        for (i, (text, color)) in entries.iter().enumerate() {
            let ty = y + 4 + i as i64 * 10;
            self.canvas.fill_rect(x + 4, ty + 1, x + 10, ty + 5, *color);
            self.canvas.text(x + 16, ty, text, 1, BLACK);
        }
    }

    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        self.canvas.save_png(path)
    }
}

fn draw_frame(canvas: &mut Canvas, panel: &Panel, spec: &PanelSpec) {
    let (l, t) = (panel.left - 1, panel.top - 1);
    let (r, b) = (panel.left + panel.width, panel.top + panel.height);
    canvas.line((l, t), (r, t), BLACK);
    canvas.line((l, b), (r, b), BLACK);
    canvas.line((l, t), (l, b), BLACK);
    canvas.line((r, t), (r, b), BLACK);
    let axis_ticks = |lo: f64, hi: f64, log: bool| -> Vec<(f64, String)> {
        if log {
            let (a, b) = (lo.log10().ceil() as i32, hi.log10().floor() as i32);
            (a..=b).map(|e| (10f64.powi(e), format!("1E{e}"))).collect()
        } else {
            ticks(lo, hi, 5)
                .into_iter()
                .map(|v| (v, tick_label(v)))
                .collect()
        }
    };
    for (v, label) in axis_ticks(spec.x_range.0, spec.x_range.1, spec.log_x) {
        let (px, _) = panel.pixel(v, spec.y_range.0);
        canvas.line((px, b), (px, b + 4), BLACK);
        let w = Canvas::text_width(&label, 1);
        canvas.text(px - w / 2, b + 8, &label, 1, BLACK);
    }
    for (v, label) in axis_ticks(spec.y_range.0, spec.y_range.1, spec.log_y) {
        let (_, py) = panel.pixel(spec.x_range.0, v);
        canvas.line((l - 4, py), (l, py), BLACK);
        let w = Canvas::text_width(&label, 1);
        canvas.text(l - 8 - w, py - 3, &label, 1, BLACK);
    }
    let w = Canvas::text_width(spec.title, 1);
    canvas.text(
        panel.left + panel.width / 2 - w / 2,
        panel.top - 18,
        spec.title,
        1,
        BLACK,
    );
    let w = Canvas::text_width(spec.x_label, 1);
    canvas.text(
        panel.left + panel.width / 2 - w / 2,
        b + 24,
        spec.x_label,
        1,
        BLACK,
    );
    canvas.text(
        panel.left - MARGIN_LEFT + 4,
        panel.top - 18,
        spec.y_label,
        1,
        BLACK,
    );
}
