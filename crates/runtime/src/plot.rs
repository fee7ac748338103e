//! Figures on `plotters`: grids of panels with axes (linear or logarithmic),
//! points, lines, shaded maps with a colour bar, level sets and legends,
//! written as PNG and SVG. The text uses DejaVu Sans, embedded (the `dejavu`
//! crate) and registered at run time, so Greek letters and subscripts
//! (φ₁, ε, A*) render without system fonts.
//!
//! A figure records what its panels show and draws everything on `save`,
//! so one description serves both backends.

use plotters::coord::ranged1d::ValueFormatter;
use plotters::coord::Shift;
use plotters::prelude::*;
use plotters::style::{register_font, FontStyle, RGBColor};
use std::path::Path;
use std::sync::Once;

/// An RGB colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

pub const BLACK: Rgb = Rgb(0, 0, 0);
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

fn rgb(c: Rgb) -> RGBColor {
    RGBColor(c.0, c.1, c.2)
}

/// How a shaded map turns values in [0, 1] into colours.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ColorMap {
    /// White (0) to black (1).
    Grey,
    /// Viridis, perceptually uniform: dark (0) to yellow (1).
    Viridis,
}

impl ColorMap {
    /// The colour at v ∈ [0, 1] (for points coloured by a value).
    pub fn rgb(self, v: f64) -> Rgb {
        let RGBColor(r, g, b) = self.color(v);
        Rgb(r, g, b)
    }

    fn color(self, v: f64) -> RGBColor {
        let v = v.clamp(0.0, 1.0);
        match self {
            ColorMap::Grey => {
                let g = (255.0 * (1.0 - v)) as u8;
                RGBColor(g, g, g)
            }
            ColorMap::Viridis => ViridisRGB::get_color(v),
        }
    }
}

/// What a panel shows: its title, axis labels, ranges and scales.
#[derive(Clone, Copy)]
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
    pub fn log_y(mut self) -> Self {
        self.log_y = true;
        self
    }
    pub fn log_log(mut self) -> Self {
        self.log_x = true;
        self.log_y = true;
        self
    }
}

/// A panel's data ranges and scales, as a scene may read them back.
#[derive(Clone, Debug)]
pub struct Panel {
    pub title: String,
    pub x_label: String,
    pub y_label: String,
    pub x_range: (f64, f64),
    pub y_range: (f64, f64),
    pub log_x: bool,
    pub log_y: bool,
}

#[derive(Clone)]
enum Layer {
    Points(Vec<(f64, f64)>, Rgb, i64),
    Line(Vec<(f64, f64)>, Rgb),
    Dashed(Vec<(f64, f64)>, Rgb),
    Map {
        columns: usize,
        rows: usize,
        values: Vec<f64>,
        map: ColorMap,
        label: String,
    },
    Contours(Vec<(f64, f64)>, Rgb, u32),
    Legend(Vec<(String, Rgb)>, bool),
    /// Cells of a grid over the panel, each its own colour (None: white).
    Cells {
        columns: usize,
        rows: usize,
        colors: Vec<Option<Rgb>>,
    },
}

/// A figure of one or more panels in a grid.
#[derive(Clone)]
pub struct Figure {
    columns: usize,
    rows: usize,
    panel_size: (u32, u32),
    panels: Vec<Panel>,
    layers: Vec<Vec<Layer>>,
}

const FONT: &str = "sans-serif";

fn register_fonts() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        // The bytes are valid TrueType (a fixed asset of the dejavu crate).
        let _ = register_font(FONT, FontStyle::Normal, dejavu::sans::regular());
        let _ = register_font(FONT, FontStyle::Bold, dejavu::sans::bold());
    });
}

impl Figure {
    /// A grid of `columns` × `rows` panels, each `panel_w` × `panel_h` pixels.
    pub fn grid(
        columns: usize,
        rows: usize,
        panel_w: usize,
        panel_h: usize,
        specs: &[PanelSpec],
    ) -> Figure {
        let panels: Vec<Panel> = specs
            .iter()
            .map(|s| Panel {
                title: s.title.to_string(),
                x_label: s.x_label.to_string(),
                y_label: s.y_label.to_string(),
                x_range: sane_range(s.x_range, s.log_x),
                y_range: sane_range(s.y_range, s.log_y),
                log_x: s.log_x,
                log_y: s.log_y,
            })
            .collect();
        Figure {
            columns: columns.max(1),
            rows: rows.max(1),
            panel_size: (panel_w as u32, panel_h as u32),
            layers: panels.iter().map(|_| Vec::new()).collect(),
            panels,
        }
    }

    pub fn single(width: usize, height: usize, spec: PanelSpec) -> Figure {
        Figure::grid(1, 1, width, height, &[spec])
    }

    pub fn panel(&self, k: usize) -> Panel {
        self.panels[k].clone()
    }

    /// Dots at data points (1 pixel, or a small square for `size` > 1).
    pub fn points(
        &mut self,
        k: usize,
        points: impl IntoIterator<Item = (f64, f64)>,
        color: Rgb,
        size: i64,
    ) {
        let pts: Vec<(f64, f64)> = points
            .into_iter()
            .filter(|(x, y)| x.is_finite() && y.is_finite())
            .collect();
        self.layers[k].push(Layer::Points(pts, color, size));
    }

    /// A polyline; it is broken where a point is not finite.
    pub fn line(&mut self, k: usize, points: &[(f64, f64)], color: Rgb) {
        self.layers[k].push(Layer::Line(points.to_vec(), color));
    }

    /// A dashed polyline (an unstable branch beside a stable one, solid).
    pub fn dashed_line(&mut self, k: usize, points: &[(f64, f64)], color: Rgb) {
        self.layers[k].push(Layer::Dashed(points.to_vec(), color));
    }

    /// Fills the panel with a map of values in [0, 1] (row 0 at the bottom,
    /// non-finite values left white) in the colour map `map`, with a colour
    /// bar labelled `label`.
    pub fn shaded_map(
        &mut self,
        k: usize,
        columns: usize,
        rows: usize,
        values: &[f64],
        map: ColorMap,
        label: &str,
    ) {
        self.layers[k].insert(
            0,
            Layer::Map {
                columns,
                rows,
                values: values.to_vec(),
                map,
                label: label.to_string(),
            },
        );
    }

    /// Fills the panel with a grid of cells (row 0 at the bottom), each in
    /// its own colour (None: left white), edge to edge: a map of
    /// categories, such as the basins of attraction.
    pub fn cells(&mut self, k: usize, columns: usize, rows: usize, colors: Vec<Option<Rgb>>) {
        self.layers[k].insert(
            0,
            Layer::Cells {
                columns,
                rows,
                colors,
            },
        );
    }

    /// Level sets of `f` with spacing `step` (and the level `special`, drawn
    /// in `special_color`): marked where f crosses a level between
    /// neighbouring points of a 400 × 400 grid over the panel.
    pub fn contours(
        &mut self,
        k: usize,
        f: &dyn Fn(f64, f64) -> f64,
        step: f64,
        color: Rgb,
        special: f64,
        special_color: Rgb,
    ) {
        let p = &self.panels[k];
        let n = 400;
        let (x0, x1, y0, y1) = (p.x_range.0, p.x_range.1, p.y_range.0, p.y_range.1);
        let at = |i: usize, j: usize| {
            let (x, y) = (
                x0 + (x1 - x0) * i as f64 / (n - 1) as f64,
                y0 + (y1 - y0) * j as f64 / (n - 1) as f64,
            );
            ((x, y), f(x, y))
        };
        let grid: Vec<((f64, f64), f64)> = (0..n)
            .flat_map(|j| (0..n).map(move |i| (i, j)))
            .map(|(i, j)| at(i, j))
            .collect();
        let (mut levels, mut specials) = (Vec::new(), Vec::new());
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let (xy, a) = grid[j * n + i];
                for (_, b) in [grid[j * n + i + 1], grid[(j + 1) * n + i]] {
                    if (a - special).signum() != (b - special).signum() {
                        specials.push(xy);
                    } else if (a / step).floor() != (b / step).floor() {
                        levels.push(xy);
                    }
                }
            }
        }
        self.layers[k].push(Layer::Contours(levels, color, 1));
        self.layers[k].push(Layer::Contours(specials, special_color, 2));
    }

    /// Legend lines in the panel's top-left corner, each with a colour swatch.
    pub fn legend(&mut self, k: usize, entries: &[(String, Rgb)]) {
        self.legend_at(k, entries, false);
    }

    /// Legend lines in the top-left or (`bottom`) bottom-left corner.
    pub fn legend_at(&mut self, k: usize, entries: &[(String, Rgb)], bottom: bool) {
        self.layers[k].push(Layer::Legend(entries.to_vec(), bottom));
    }

    /// Whether an SVG of this figure stays small: no shaded map and at most
    /// 50 000 drawn points (orbit clouds belong in PNG).
    pub fn svg_is_cheap(&self) -> bool {
        let mut points = 0;
        for layer in self.layers.iter().flatten() {
            points += match layer {
                Layer::Map { .. } | Layer::Cells { .. } => return false,
                Layer::Points(p, ..)
                | Layer::Line(p, _)
                | Layer::Dashed(p, _)
                | Layer::Contours(p, ..) => p.len(),
                Layer::Legend(..) => 0,
            };
        }
        points <= 50_000
    }

    fn size(&self) -> (u32, u32) {
        (
            self.panel_size.0 * self.columns as u32,
            self.panel_size.1 * self.rows as u32,
        )
    }

    /// Writes the figure as PNG: drawn into an RGB buffer and encoded with
    /// the `png` crate (plotters' own encoder would compile the `image`
    /// crate and its JPEG decoder, 20 s of a fresh build, for this alone).
    pub fn save(&self, path: &Path) -> std::io::Result<()> {
        register_fonts();
        let (width, height) = self.size();
        let mut pixels = vec![0u8; 3 * width as usize * height as usize];
        {
            let root = BitMapBackend::with_buffer(&mut pixels, (width, height)).into_drawing_area();
            self.draw(&root).map_err(std::io::Error::other)?;
            root.present()
                .map_err(|e| std::io::Error::other(e.to_string()))?;
        }
        let file = std::io::BufWriter::new(std::fs::File::create(path)?);
        let mut encoder = png::Encoder::new(file, width, height);
        encoder.set_color(png::ColorType::Rgb);
        encoder.set_depth(png::BitDepth::Eight);
        let mut writer = encoder.write_header().map_err(std::io::Error::other)?;
        writer
            .write_image_data(&pixels)
            .map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)
    }

    /// Writes the figure as SVG.
    pub fn save_svg(&self, path: &Path) -> std::io::Result<()> {
        register_fonts();
        let root = SVGBackend::new(path, self.size()).into_drawing_area();
        self.draw(&root).map_err(std::io::Error::other)?;
        root.present()
            .map_err(|e| std::io::Error::other(e.to_string()))
    }

    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError>
    where
        DB::ErrorType: 'static,
    {
        root.fill(&WHITE_COLOR).map_err(|e| DrawError {
            panel: String::new(),
            source: e.into(),
        })?;
        let areas = root.split_evenly((self.rows, self.columns));
        for ((panel, layers), area) in self.panels.iter().zip(&self.layers).zip(&areas) {
            draw_panel(area, panel, layers).map_err(|source| DrawError {
                panel: panel.title.clone(),
                source,
            })?;
        }
        Ok(())
    }
}

const WHITE_COLOR: RGBColor = RGBColor(255, 255, 255);

/// A short tick label: round-off hidden (12 significant digits), powers of
/// ten as 1e-4, no trailing zeros.
fn tick_label(v: f64) -> String {
    // Ticks at zero come out of the tick arithmetic as ±1e-17 or so.
    if v.abs() < 1e-15 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            format!("{v}")
        };
    }
    let v: f64 = format!("{v:.11e}").parse().unwrap_or(v);
    let a = v.abs();
    if !(1e-3..1e5).contains(&a) {
        let s = format!("{v:e}");
        match s.split_once('e') {
            Some((mantissa, exponent)) => {
                let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
                if mantissa == "1" {
                    format!("1e{exponent}")
                } else {
                    format!("{mantissa}e{exponent}")
                }
            }
            None => s,
        }
    } else {
        let s = format!("{v:.6}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// A usable axis range: ordered, not empty, positive on a log axis.
fn sane_range((lo, hi): (f64, f64), log: bool) -> (f64, f64) {
    let (mut lo, mut hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    if !lo.is_finite() || !hi.is_finite() {
        return if log { (0.1, 10.0) } else { (0.0, 1.0) };
    }
    if log {
        lo = lo.max(1e-300);
        hi = hi.max(lo * 10.0);
    } else if hi - lo <= 1e-9 * lo.abs().max(hi.abs()) || hi - lo <= 1e-300 {
        // A constant series (to rounding, as a conserved momentum): a
        // range around it wide enough for the ticks to differ in their
        // labels, the series a flat line in its middle.
        let size = lo.abs().max(hi.abs());
        let pad = if size > 0.0 { 0.05 * size } else { 1.0 };
        lo -= pad;
        hi += pad;
    }
    (lo, hi)
}

/// What plotters reports (its error type depends on the backend).
type PlotFailure = Box<dyn std::error::Error + Send + Sync>;

/// A figure that could not be drawn: the panel (empty for the whole
/// figure) and plotters' error.
#[derive(Debug, thiserror::Error)]
#[error("panel '{panel}': {source}")]
pub struct DrawError {
    pub panel: String,
    pub source: PlotFailure,
}

type Chart<'a, DB, X, Y> = ChartContext<'a, DB, Cartesian2d<X, Y>>;

fn draw_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    panel: &Panel,
    layers: &[Layer],
) -> Result<(), PlotFailure>
where
    DB::ErrorType: 'static,
{
    let map_label = layers.iter().find_map(|l| match l {
        Layer::Map { map, label, .. } => Some((*map, label.clone())),
        _ => None,
    });
    // A shaded map gets a colour bar on the right.
    let (plot_area, bar_area) = match &map_label {
        Some(_) => {
            let (w, _) = area.dim_in_pixel();
            let (a, b) = area.split_horizontally(w.saturating_sub(70));
            (a, Some(b))
        }
        None => (area.clone(), None),
    };
    let mut builder = ChartBuilder::on(&plot_area);
    builder
        .caption(&panel.title, (FONT, 15))
        .margin(8)
        .x_label_area_size(40)
        .y_label_area_size(62);
    let (x, y) = (
        panel.x_range.0..panel.x_range.1,
        panel.y_range.0..panel.y_range.1,
    );
    let (xs, ys) = match (panel.log_x, panel.log_y) {
        (false, false) => {
            let mut c = builder.build_cartesian_2d(x, y)?;
            fill(&mut c, panel, layers)
        }
        (true, false) => {
            let mut c = builder.build_cartesian_2d(x.log_scale(), y)?;
            fill(&mut c, panel, layers)
        }
        (false, true) => {
            let mut c = builder.build_cartesian_2d(x, y.log_scale())?;
            fill(&mut c, panel, layers)
        }
        (true, true) => {
            let mut c = builder.build_cartesian_2d(x.log_scale(), y.log_scale())?;
            fill(&mut c, panel, layers)
        }
    }?;
    // The axes' names, a subscript set as one (p_φ₁: p with φ₁ below).
    let (left, top) = plot_area.get_base_pixel();
    let middle = |r: &std::ops::Range<i32>| (r.start + r.end) / 2;
    let below = (middle(&xs) - left, ys.end - top + 24);
    axis_name(&plot_area, &panel.x_label, below, false)?;
    let beside = (xs.start - left - 56, middle(&ys) - top);
    axis_name(&plot_area, &panel.y_label, beside, true)?;
    if let (Some(bar), Some((map, label))) = (bar_area, map_label) {
        color_bar(&bar, map, &label)?;
    }
    Ok(())
}

/// Draws an axis's name centred at `at` (pixels of `area`; `upward`: the
/// y axis's, read from below), the part after `_` as a subscript: smaller,
/// and lowered.
fn axis_name<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    name: &str,
    at: (i32, i32),
    upward: bool,
) -> Result<(), PlotFailure>
where
    DB::ErrorType: 'static,
{
    let (base, subscript) = name.split_once('_').unwrap_or((name, ""));
    let turn = if upward {
        FontTransform::Rotate270
    } else {
        FontTransform::None
    };
    let big = TextStyle::from((FONT, 14).into_font());
    let small = TextStyle::from((FONT, 11).into_font());
    // (Measured upright: the length along the text.)
    let width = |text: &str, style: &TextStyle| {
        area.estimate_text_size(text, style)
            .map(|(w, _)| w as i32)
            .unwrap_or(0)
    };
    let (wide, sub_wide) = (width(base, &big), width(subscript, &small));
    let (big, small) = (big.transform(turn.clone()), small.transform(turn));
    let start = (wide + sub_wide) / 2;
    let (text_at, sub_at) = if upward {
        let y = at.1 + start;
        ((at.0, y), (at.0 + 5, y - wide))
    } else {
        let x = at.0 - start;
        ((x, at.1), (x + wide, at.1 + 5))
    };
    area.draw(&Text::new(base.to_string(), text_at, big))?;
    if !subscript.is_empty() {
        area.draw(&Text::new(subscript.to_string(), sub_at, small))?;
    }
    Ok(())
}

/// A vertical colour bar for values 0..1.
fn color_bar<DB: DrawingBackend>(
    area: &DrawingArea<DB, Shift>,
    map: ColorMap,
    label: &str,
) -> Result<(), PlotFailure>
where
    DB::ErrorType: 'static,
{
    let mut chart = ChartBuilder::on(area)
        .margin_top(30)
        .margin_bottom(48)
        .margin_right(30)
        .y_label_area_size(0)
        .right_y_label_area_size(30)
        .build_cartesian_2d(0.0..1.0, 0.0..1.0)?;
    let n = 100;
    chart.draw_series((0..n).map(|i| {
        let (a, b) = (i as f64 / n as f64, (i + 1) as f64 / n as f64);
        Rectangle::new([(0.0, a), (1.0, b)], map.color(0.5 * (a + b)).filled())
    }))?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .disable_y_mesh()
        .disable_x_axis()
        .y_labels(6)
        .y_desc(label)
        .label_style((FONT, 12))
        .draw()
        .map_err(PlotFailure::from)
}

fn fill<'a, DB, X, Y>(
    chart: &mut Chart<'a, DB, X, Y>,
    panel: &Panel,
    layers: &[Layer],
) -> Result<(std::ops::Range<i32>, std::ops::Range<i32>), PlotFailure>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotFailure::from(e);
    // Only what lies in the panel is drawn (plotters would pile the rest
    // up on the frame); lines are broken where they leave it.
    let inside = |v: f64, (lo, hi): (f64, f64)| {
        let pad = 1e-9 * (hi - lo).abs();
        v >= lo - pad && v <= hi + pad
    };
    let visible = |&(x, y): &(f64, f64)| {
        x.is_finite() && y.is_finite() && inside(x, panel.x_range) && inside(y, panel.y_range)
    };
    chart
        .configure_mesh()
        .label_style((FONT, 12))
        .light_line_style(RGBColor(235, 235, 235))
        .bold_line_style(RGBColor(215, 215, 215))
        .x_labels(6)
        .y_labels(6)
        .x_label_formatter(&|v| tick_label(*v))
        .y_label_formatter(&|v| tick_label(*v))
        .draw()
        .map_err(err)?;
    for layer in layers {
        match layer {
            Layer::Map {
                columns,
                rows,
                values,
                map,
                ..
            } => {
                // Non-finite values are left blank.
                let colors: Vec<Option<Rgb>> = values
                    .iter()
                    .map(|&v| v.is_finite().then(|| map.rgb(v)))
                    .collect();
                draw_cells(chart, panel, [*columns, *rows], &colors)?
            }
            Layer::Cells {
                columns,
                rows,
                colors,
            } => draw_cells(chart, panel, [*columns, *rows], colors)?,
            Layer::Points(pts, color, size) => {
                let c = rgb(*color);
                if *size <= 1 {
                    chart
                        .draw_series(pts.iter().filter(|p| visible(p)).map(|p| Pixel::new(*p, c)))
                        .map_err(err)?;
                } else {
                    let r = (*size / 2).max(1) as i32;
                    chart
                        .draw_series(pts.iter().filter(|p| visible(p)).map(|p| {
                            EmptyElement::at(*p) + Rectangle::new([(-r, -r), (r, r)], c.filled())
                        }))
                        .map_err(err)?;
                }
            }
            Layer::Contours(pts, color, size) => {
                let (c, r) = (rgb(*color), *size as i32);
                chart
                    .draw_series(pts.iter().filter(|p| visible(p)).map(|p| {
                        EmptyElement::at(*p) + Rectangle::new([(0, 0), (r, r)], c.filled())
                    }))
                    .map_err(err)?;
            }
            Layer::Line(pts, color) => {
                let c = rgb(*color);
                // Broken where a point cannot be drawn.
                for piece in pts.split(|p| !visible(p)) {
                    if piece.len() > 1 {
                        chart
                            .draw_series(LineSeries::new(piece.iter().copied(), c.stroke_width(1)))
                            .map_err(err)?;
                    }
                }
            }
            Layer::Dashed(pts, color) => {
                let c = rgb(*color);
                for piece in pts.split(|p| !visible(p)) {
                    if piece.len() > 1 {
                        chart
                            .draw_series(DashedLineSeries::new(
                                piece.iter().copied(),
                                6,
                                4,
                                c.stroke_width(1),
                            ))
                            .map_err(err)?;
                    }
                }
            }
            Layer::Legend(entries, bottom) => draw_legend(chart, entries, *bottom)?,
        }
    }
    Ok(chart.plotting_area().get_pixel_range())
}

/// A grid of cells, each filled with its colour edge to edge.
fn draw_cells<'a, DB, X, Y>(
    chart: &mut Chart<'a, DB, X, Y>,
    panel: &Panel,
    [columns, rows]: [usize; 2],
    colors: &[Option<Rgb>],
) -> Result<(), PlotFailure>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let (x0, x1) = panel.x_range;
    let (y0, y1) = panel.y_range;
    let (dx, dy) = ((x1 - x0) / columns as f64, (y1 - y0) / rows as f64);
    let cells = colors.iter().enumerate().filter_map(|(k, color)| {
        let (x, y) = (
            x0 + (k % columns) as f64 * dx,
            y0 + (k / columns) as f64 * dy,
        );
        color.map(|c| Rectangle::new([(x, y), (x + dx, y + dy)], rgb(c).filled()))
    });
    chart
        .draw_series(cells)
        .map_err(|e: DrawingAreaErrorKind<DB::ErrorType>| PlotFailure::from(e))?;
    Ok(())
}

/// A legend layer: a coloured box per entry, at the lower or upper left.
fn draw_legend<'a, DB, X, Y>(
    chart: &mut Chart<'a, DB, X, Y>,
    entries: &[(String, Rgb)],
    bottom: bool,
) -> Result<(), PlotFailure>
where
    DB: DrawingBackend + 'a,
    DB::ErrorType: 'static,
    X: Ranged<ValueType = f64> + ValueFormatter<f64>,
    Y: Ranged<ValueType = f64> + ValueFormatter<f64>,
{
    let err = |e: DrawingAreaErrorKind<DB::ErrorType>| PlotFailure::from(e);
    for (text, color) in entries {
        let c = rgb(*color);
        chart
            .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
            .map_err(err)?
            .label(text.as_str())
            .legend(move |(x, y)| Rectangle::new([(x, y - 4), (x + 12, y + 4)], c.filled()));
    }
    chart
        .configure_series_labels()
        .position(if bottom {
            SeriesLabelPosition::LowerLeft
        } else {
            SeriesLabelPosition::UpperLeft
        })
        .label_font((FONT, 12))
        .background_style(WHITE_COLOR.mix(0.85))
        .border_style(RGBColor(180, 180, 180))
        .draw()
        .map_err(err)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::sane_range;

    /// A constant series (a conserved momentum, to rounding) gets a range
    /// of ±5 % around it, wide enough for its ticks to be told apart;
    /// a varying one keeps its own.
    #[test]
    fn a_constant_series_gets_a_range_its_ticks_can_label() {
        let (lo, hi) = sane_range((0.8, 0.8 + 1e-16), false);
        assert!(
            (lo - 0.76).abs() < 1e-12 && (hi - 0.84).abs() < 1e-12,
            "{lo} {hi}"
        );
        assert_eq!(sane_range((0.0, 0.0), false), (-1.0, 1.0));
        assert_eq!(sane_range((-8e-9, 1.5e-8), false), (-8e-9, 1.5e-8));
    }
}
