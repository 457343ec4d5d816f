//! Scene text to a [`RefScene`], written from the format's documentation alone; errors as `line:col: message`.

use crate::bspline::Patch;
use crate::vector::{Rgb, V3};
use crate::{Light, Object, RefScene, Shape, Surface};
use std::collections::BTreeMap;

struct Token {
    text: String,
    line: usize,
    col: usize,
}

fn tokenize(text: &str) -> Result<Vec<Token>, String> {
    let chars: Vec<char> = text.chars().collect();
    let mut tokens = Vec::new();
    let (mut i, mut line, mut col) = (0usize, 1usize, 1usize);
    // Advance one character, keeping line and column up to date.
    let step = |i: &mut usize, line: &mut usize, col: &mut usize| {
        if chars[*i] == '\n' {
            *line += 1;
            *col = 1;
        } else {
            *col += 1;
        }
        *i += 1;
    };
    let comment_start = |i: usize| -> Option<char> {
        if chars[i] == '/' && i + 1 < chars.len() && (chars[i + 1] == '*' || chars[i + 1] == '/') {
            Some(chars[i + 1])
        } else {
            None
        }
    };
    while i < chars.len() {
        let c = chars[i];
        if c.is_whitespace() {
            step(&mut i, &mut line, &mut col);
        } else if comment_start(i) == Some('/') {
            while i < chars.len() && chars[i] != '\n' {
                step(&mut i, &mut line, &mut col);
            }
        } else if comment_start(i) == Some('*') {
            let (open_line, open_col) = (line, col);
            step(&mut i, &mut line, &mut col);
            step(&mut i, &mut line, &mut col);
            loop {
                if i >= chars.len() {
                    return Err(format!("{open_line}:{open_col}: unterminated comment opened on line {open_line}"));
                }
                if chars[i] == '*' && i + 1 < chars.len() && chars[i + 1] == '/' {
                    step(&mut i, &mut line, &mut col);
                    step(&mut i, &mut line, &mut col);
                    break;
                }
                step(&mut i, &mut line, &mut col);
            }
        } else if c == '"' {
            let (tl, tc) = (line, col);
            step(&mut i, &mut line, &mut col);
            let mut s = String::new();
            loop {
                if i >= chars.len() {
                    return Err(format!("{tl}:{tc}: unterminated quoted string"));
                }
                if chars[i] == '"' {
                    step(&mut i, &mut line, &mut col);
                    break;
                }
                s.push(chars[i]);
                step(&mut i, &mut line, &mut col);
            }
            tokens.push(Token { text: s, line: tl, col: tc });
        } else {
            let (tl, tc) = (line, col);
            let mut s = String::new();
            while i < chars.len() && !chars[i].is_whitespace() && comment_start(i).is_none() {
                s.push(chars[i]);
                step(&mut i, &mut line, &mut col);
            }
            tokens.push(Token { text: s, line: tl, col: tc });
        }
    }
    Ok(tokens)
}

/// True when `s` is `[+-]? digits? (. digits?)? ([eE] [+-]? digits)?` with at
/// least one mantissa digit.
fn is_number(s: &str) -> bool {
    let (mantissa, exponent) = match s.find(['e', 'E']) {
        Some(at) => (&s[..at], Some(&s[at + 1..])),
        None => (s, None),
    };
    let unsigned = mantissa.strip_prefix(['+', '-']).unwrap_or(mantissa);
    let (whole, fraction) = unsigned.split_once('.').unwrap_or((unsigned, ""));
    let all_digits = |t: &str| t.bytes().all(|c| c.is_ascii_digit());
    all_digits(whole)
        && all_digits(fraction)
        && !(whole.is_empty() && fraction.is_empty())
        && exponent.is_none_or(is_integer)
}

fn is_integer(s: &str) -> bool {
    let digits = s.strip_prefix(['+', '-']).unwrap_or(s);
    !digits.is_empty() && digits.bytes().all(|c| c.is_ascii_digit())
}

struct Parser {
    tokens: Vec<Token>,
    pos: usize,
    /// Position reported for "unexpected end of file".
    end: (usize, usize),
}

impl Parser {
    fn next(&mut self, what: &str) -> Result<&Token, String> {
        match self.tokens.get(self.pos) {
            Some(t) => {
                self.pos += 1;
                Ok(t)
            }
            None => Err(format!("{}:{}: expected {what}, found end of file", self.end.0, self.end.1)),
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, String> {
        let t = self.next(what)?;
        let v = if is_number(&t.text) { t.text.parse::<f64>().ok() } else { None };
        match v {
            Some(v) if v.abs() <= 1e6 => Ok(v),
            Some(v) => Err(format!("{}:{}: {what} is out of range (magnitude above 1e6), found {v}", t.line, t.col)),
            None => Err(format!("{}:{}: expected {what} (a number), found `{}`", t.line, t.col, t.text)),
        }
    }

    fn integer(&mut self, what: &str, min: i64, max: i64) -> Result<i64, String> {
        let t = self.next(what)?;
        let v = if is_integer(&t.text) { t.text.parse::<i64>().ok() } else { None };
        match v {
            Some(v) if (min..=max).contains(&v) => Ok(v),
            Some(v) => Err(format!("{}:{}: {what} must be in {min}..={max}, found {v}", t.line, t.col)),
            None => Err(format!("{}:{}: expected {what} (an integer), found `{}`", t.line, t.col, t.text)),
        }
    }

    /// A number that must satisfy `ok`; `rule` describes the requirement.
    fn checked(&mut self, what: &str, rule: &str, ok: impl Fn(f64) -> bool) -> Result<f64, String> {
        let (line, col) = self.tokens.get(self.pos).map_or(self.end, |t| (t.line, t.col));
        let v = self.number(what)?;
        if ok(v) {
            Ok(v)
        } else {
            Err(format!("{line}:{col}: {what} must be {rule}, found {v}"))
        }
    }

    fn vec3(&mut self, what: &str) -> Result<V3, String> {
        Ok(V3::new(self.number(what)?, self.number(what)?, self.number(what)?))
    }

    fn colour(&mut self, what: &str) -> Result<Rgb, String> {
        Ok([self.number(what)?, self.number(what)?, self.number(what)?])
    }
}

/// Parse a scene. Errors are `line:col: message`.
pub fn parse(text: &str) -> Result<RefScene, String> {
    let tokens = tokenize(text)?;
    let end = {
        let lines = text.split('\n').count().max(1);
        let last_col = text.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
        (lines, last_col)
    };
    let mut p = Parser { tokens, pos: 0, end };

    let mut scene = RefScene {
        viewpoint: V3::new(0.0, 0.0, 10.0),
        origin: V3::new(0.0, 0.0, 0.0),
        upvector: V3::new(0.0, 1.0, 0.0),
        raster: (320, 240),
        viewport: None,
        rdepth: 3,
        imagefile: None,
        lights: Vec::new(),
        background: [0.0; 3],
        gamma: 2.2,
        attenuation: 1.0,
        samples: 1,
        objects: Vec::new(),
        surfaces: Vec::new(),
    };
    // Scene parameters seen so far, with the line they were given on.
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    // Surface number -> index in scene.surfaces.
    let mut surface_index: BTreeMap<i64, usize> = BTreeMap::new();
    // For each object: the surface number it refers to and where.
    let mut references: Vec<(i64, usize, usize)> = Vec::new();

    while p.pos < p.tokens.len() {
        let (line, col) = (p.tokens[p.pos].line, p.tokens[p.pos].col);
        let keyword = p.tokens[p.pos].text.to_ascii_uppercase();
        p.pos += 1;
        let is_parameter = matches!(
            keyword.as_str(),
            "VIEWPOINT"
                | "ORIGIN"
                | "UPVECTOR"
                | "RASTER"
                | "VIEWPORT"
                | "RDEPTH"
                | "IMAGEFILE"
                | "BACKGROUND"
                | "GAMMA"
                | "ATTENUATION"
                | "SAMPLES"
        );
        if is_parameter {
            if let Some(first) = seen.insert(keyword.clone(), line) {
                return Err(format!("{line}:{col}: {keyword} given twice (lines {first} and {line})"));
            }
        }
        match keyword.as_str() {
            "VIEWPOINT" => scene.viewpoint = p.vec3("VIEWPOINT coordinate")?,
            "ORIGIN" => scene.origin = p.vec3("ORIGIN coordinate")?,
            "UPVECTOR" => scene.upvector = p.vec3("UPVECTOR component")?,
            "RASTER" => {
                let w = p.integer("RASTER width", 1, 16384)?;
                let h = p.integer("RASTER height", 1, 16384)?;
                scene.raster = (w as u32, h as u32);
            }
            "VIEWPORT" => {
                let w = p.checked("VIEWPORT width", "> 0", |v| v > 0.0)?;
                let h = p.checked("VIEWPORT height", "> 0", |v| v > 0.0)?;
                scene.viewport = Some((w, h));
            }
            "RDEPTH" => scene.rdepth = p.integer("RDEPTH", 0, 1_000_000)? as u32,
            "IMAGEFILE" => scene.imagefile = Some(p.next("a file name")?.text.clone()),
            "LIGHT" => {
                let brightness = p.checked("LIGHT brightness", ">= 0", |v| v >= 0.0)?;
                let position = p.vec3("LIGHT coordinate")?;
                scene.lights.push(Light { brightness, position });
            }
            "BACKGROUND" => scene.background = p.colour("BACKGROUND component")?,
            "GAMMA" => scene.gamma = p.checked("GAMMA", "> 0", |v| v > 0.0)?,
            "ATTENUATION" => scene.attenuation = p.checked("ATTENUATION", "> 0", |v| v > 0.0)?,
            "SAMPLES" => scene.samples = p.integer("SAMPLES", 1, 16)? as u32,
            "SURFACE" => {
                let n = p.integer("surface number", 0, 1_000_000)?;
                let surface = Surface {
                    ambient: p.colour("ambient colour")?,
                    diffuse: p.colour("diffuse colour")?,
                    specular: p.colour("specular colour")?,
                    exponent: p.checked("specular exponent", ">= 0", |v| v >= 0.0)?,
                    reflectivity: p.number("reflectivity")?,
                    transparency: p.number("transparency")?,
                };
                if surface_index.insert(n, scene.surfaces.len()).is_some() {
                    return Err(format!("{line}:{col}: SURFACE {n} defined twice"));
                }
                scene.surfaces.push(surface);
            }
            "SPHERE" | "BOX" | "SUPERQUADRIC" | "TRIANGLE" | "RECTANGLE" => {
                let s = p.integer("surface number", 0, 1_000_000)?;
                let shape = parse_shape(&mut p, &keyword, line, col)?;
                references.push((s, line, col));
                scene.objects.push(Object { shape, surface: 0 });
            }
            "BSPLINE" => {
                let s = p.integer("surface number", 0, 1_000_000)?;
                let order = p.integer("BSPLINE order", 2, 8)? as usize;
                let rows = p.integer("BSPLINE rows", 2, 1024)? as usize;
                let cols = p.integer("BSPLINE cols", 2, 1024)? as usize;
                let su = p.integer("BSPLINE su", 2, 1024)? as usize;
                let sv = p.integer("BSPLINE sv", 2, 1024)? as usize;
                if rows < order || cols < order {
                    return Err(format!("{line}:{col}: BSPLINE needs at least `order` control points each way"));
                }
                let mut points = Vec::with_capacity(rows * cols);
                for _ in 0..rows * cols {
                    points.push(p.vec3("BSPLINE control point")?);
                }
                let patch = Patch { order, rows, cols, points };
                let before = scene.objects.len();
                for shape in patch.triangles(su, sv) {
                    references.push((s, line, col));
                    scene.objects.push(Object { shape, surface: 0 });
                }
                if scene.objects.len() == before {
                    return Err(format!("{line}:{col}: degenerate BSPLINE"));
                }
            }
            _ => return Err(format!("{line}:{col}: expected a keyword, found `{}`", p.tokens[p.pos - 1].text)),
        }
    }

    for (object, &(s, line, col)) in scene.objects.iter_mut().zip(&references) {
        object.surface = *surface_index.get(&s).ok_or_else(|| format!("{line}:{col}: surface {s} is not defined"))?;
    }

    let forward = scene.origin - scene.viewpoint;
    if forward.length() == 0.0 {
        return Err("1:1: VIEWPOINT equals ORIGIN".to_string());
    }
    if forward.cross(scene.upvector).length() == 0.0 {
        return Err("1:1: UPVECTOR is parallel to the view direction".to_string());
    }
    Ok(scene)
}

fn parse_shape(p: &mut Parser, keyword: &str, line: usize, col: usize) -> Result<Shape, String> {
    let positive = |v: f64| v > 0.0;
    let degenerate = || Err(format!("{line}:{col}: degenerate {keyword}"));
    Ok(match keyword {
        "SPHERE" => {
            let radius = p.checked("SPHERE radius", "> 0", positive)?;
            Shape::Sphere { centre: p.vec3("SPHERE centre")?, radius }
        }
        "BOX" => {
            let centre = p.vec3("BOX centre")?;
            let half = V3::new(
                p.checked("BOX half-size", "> 0", positive)?,
                p.checked("BOX half-size", "> 0", positive)?,
                p.checked("BOX half-size", "> 0", positive)?,
            );
            Shape::Box { centre, half }
        }
        "SUPERQUADRIC" => {
            let power = p.checked("SUPERQUADRIC power", "in 2..=64", |v| (2.0..=64.0).contains(&v))?;
            let centre = p.vec3("SUPERQUADRIC centre")?;
            let half = V3::new(
                p.checked("SUPERQUADRIC size", "> 0", positive)?,
                p.checked("SUPERQUADRIC size", "> 0", positive)?,
                p.checked("SUPERQUADRIC size", "> 0", positive)?,
            );
            Shape::Superquadric { power, centre, half }
        }
        "TRIANGLE" => {
            let pts = [p.vec3("TRIANGLE corner")?, p.vec3("TRIANGLE corner")?, p.vec3("TRIANGLE corner")?];
            let n = (pts[1] - pts[0]).cross(pts[2] - pts[0]);
            if n.length() == 0.0 {
                return degenerate();
            }
            Shape::Triangle { p: pts, normal: n.normalised() }
        }
        _ => {
            let pts = [
                p.vec3("RECTANGLE corner")?,
                p.vec3("RECTANGLE corner")?,
                p.vec3("RECTANGLE corner")?,
                p.vec3("RECTANGLE corner")?,
            ];
            // For a planar convex quad, the cross product of the diagonals
            // points to the side from which the corners run counter-clockwise.
            let n = (pts[2] - pts[0]).cross(pts[3] - pts[1]);
            if n.length() == 0.0 {
                return degenerate();
            }
            Shape::Rectangle { p: pts, normal: n.normalised() }
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_sign_digits_point_digits_exponent() {
        for yes in ["1", "+1", "-1", "1.", ".5", "-.5", "1.25", "1e3", "1E-3", "+2.5e+10", "0.0e0"] {
            assert!(is_number(yes), "{yes}");
        }
        for no in [
            "", "+", "-", ".", "+.", "e3", ".e3", "1e", "1e+", "1.2.3", "+-1", "1e3e4", "1e3.5", "1x", "--1", " 1",
            "1 ", "é",
        ] {
            assert!(!is_number(no), "{no}");
        }
    }
}
