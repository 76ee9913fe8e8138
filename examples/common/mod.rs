//! Drawing for the examples: an RGB canvas with anti-aliased-free lines and dots, written as
//! PNG without dependencies (stored deflate blocks; files are larger, but any viewer reads
//! them).
#![allow(dead_code)]

use std::io::Write;
use std::path::Path;

/// An RGB image with a world-to-pixel mapping.
pub struct Canvas {
    pub width: usize,
    pub height: usize,
    pixels: Vec<[u8; 3]>,
    /// World rectangle shown: (x_min, y_min, x_max, y_max).
    view: [f32; 4],
}

impl Canvas {
    pub fn new(width: usize, height: usize, view: [f32; 4], background: [u8; 3]) -> Self {
        Self {
            width,
            height,
            pixels: vec![background; width * height],
            view,
        }
    }

    /// World (x, y) to pixel (column, row), y up.
    pub fn to_pixel(&self, x: f32, y: f32) -> (f32, f32) {
        let [x0, y0, x1, y1] = self.view;
        let px = (x - x0) / (x1 - x0) * self.width as f32;
        let py = (1.0 - (y - y0) / (y1 - y0)) * self.height as f32;
        (px, py)
    }

    pub fn put(&mut self, px: i64, py: i64, color: [u8; 3]) {
        if px >= 0 && py >= 0 && (px as usize) < self.width && (py as usize) < self.height {
            self.pixels[py as usize * self.width + px as usize] = color;
        }
    }

    /// A filled disc of `radius` pixels at world (x, y).
    pub fn dot(&mut self, x: f32, y: f32, radius: i64, color: [u8; 3]) {
        let (px, py) = self.to_pixel(x, y);
        if !(px.is_finite() && py.is_finite()) {
            return;
        }
        let (cx, cy) = (px as i64, py as i64);
        for dy in -radius..=radius {
            for dx in -radius..=radius {
                if dx * dx + dy * dy <= radius * radius {
                    self.put(cx + dx, cy + dy, color);
                }
            }
        }
    }

    /// A line between world points, `thick` pixels wide.
    pub fn line(&mut self, a: (f32, f32), b: (f32, f32), thick: i64, color: [u8; 3]) {
        let (ax, ay) = self.to_pixel(a.0, a.1);
        let (bx, by) = self.to_pixel(b.0, b.1);
        if !(ax.is_finite() && ay.is_finite() && bx.is_finite() && by.is_finite()) {
            return;
        }
        let n = ((bx - ax).abs().max((by - ay).abs()).ceil() as i64).clamp(1, 10_000);
        for i in 0..=n {
            let t = i as f32 / n as f32;
            let (x, y) = (ax + (bx - ax) * t, ay + (by - ay) * t);
            for dy in 0..thick {
                for dx in 0..thick {
                    self.put(x as i64 + dx - thick / 2, y as i64 + dy - thick / 2, color);
                }
            }
        }
    }

    /// A polyline through world points.
    pub fn polyline(&mut self, points: &[(f32, f32)], thick: i64, color: [u8; 3]) {
        for w in points.windows(2) {
            self.line(w[0], w[1], thick, color);
        }
    }

    /// Axis-aligned rectangle outline in pixel space (for plot frames).
    pub fn frame(&mut self, x0: i64, y0: i64, x1: i64, y1: i64, color: [u8; 3]) {
        for x in x0..=x1 {
            self.put(x, y0, color);
            self.put(x, y1, color);
        }
        for y in y0..=y1 {
            self.put(x0, y, color);
            self.put(x1, y, color);
        }
    }

    pub fn save_png(&self, path: &Path) -> std::io::Result<()> {
        let mut raw = Vec::with_capacity((self.width * 3 + 1) * self.height);
        for row in self.pixels.chunks(self.width) {
            raw.push(0); // filter: none
            for p in row {
                raw.extend_from_slice(p);
            }
        }
        let mut out = Vec::new();
        out.extend_from_slice(b"\x89PNG\r\n\x1a\n");
        let mut ihdr = Vec::new();
        ihdr.extend_from_slice(&(self.width as u32).to_be_bytes());
        ihdr.extend_from_slice(&(self.height as u32).to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8-bit RGB
        chunk(&mut out, b"IHDR", &ihdr);
        chunk(&mut out, b"IDAT", &zlib_stored(&raw));
        chunk(&mut out, b"IEND", &[]);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::File::create(path)?.write_all(&out)
    }
}

fn chunk(out: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    out.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let start = out.len();
    out.extend_from_slice(kind);
    out.extend_from_slice(data);
    let crc = crc32(&out[start..]);
    out.extend_from_slice(&crc.to_be_bytes());
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = 0xFFFF_FFFFu32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

/// zlib stream of stored (uncompressed) deflate blocks.
fn zlib_stored(data: &[u8]) -> Vec<u8> {
    let mut out = vec![0x78, 0x01];
    let blocks: Vec<&[u8]> = data.chunks(65_535).collect();
    for (i, block) in blocks.iter().enumerate() {
        out.push(u8::from(i + 1 == blocks.len()));
        let len = block.len() as u16;
        out.extend_from_slice(&len.to_le_bytes());
        out.extend_from_slice(&(!len).to_le_bytes());
        out.extend_from_slice(block);
    }
    let (mut a, mut b) = (1u32, 0u32);
    for &byte in data {
        a = (a + u32::from(byte)) % 65_521;
        b = (b + a) % 65_521;
    }
    out.extend_from_slice(&((b << 16) | a).to_be_bytes());
    out
}

/// A colour ramp from blue (0) to orange (1).
pub fn ramp(t: f32) -> [u8; 3] {
    let t = t.clamp(0.0, 1.0);
    let lerp = |a: f32, b: f32| (a + (b - a) * t) as u8;
    [lerp(40.0, 240.0), lerp(90.0, 140.0), lerp(220.0, 30.0)]
}
