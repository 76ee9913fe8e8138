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
    pub pixels: Vec<[u8; 3]>,
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

    /// Paints every pixel `color`.
    pub fn clear(&mut self, color: [u8; 3]) {
        self.pixels.fill(color);
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

/// An animated GIF built from RGB canvases, quantised to a 6×6×6 colour cube and stored
/// with 9-bit literal LZW codes (a clear code every 250 pixels keeps the code width fixed):
/// larger than a compressing encoder's output, but valid and dependency-free.
pub struct Gif {
    width: usize,
    height: usize,
    bytes: Vec<u8>,
}

impl Gif {
    pub fn new(width: usize, height: usize) -> Self {
        let mut bytes = b"GIF89a".to_vec();
        bytes.extend_from_slice(&(width as u16).to_le_bytes());
        bytes.extend_from_slice(&(height as u16).to_le_bytes());
        bytes.extend_from_slice(&[0xF7, 0, 0]); // global table of 256 colours
        for i in 0..256u32 {
            let (r, g, b) = if i < 216 {
                (i / 36, (i / 6) % 6, i % 6)
            } else {
                (5, 5, 5)
            };
            bytes.extend_from_slice(&[(r * 51) as u8, (g * 51) as u8, (b * 51) as u8]);
        }
        // Loop forever.
        bytes.extend_from_slice(&[0x21, 0xFF, 0x0B]);
        bytes.extend_from_slice(b"NETSCAPE2.0");
        bytes.extend_from_slice(&[0x03, 0x01, 0x00, 0x00, 0x00]);
        Self {
            width,
            height,
            bytes,
        }
    }

    /// Appends a frame shown for `delay_cs` hundredths of a second.
    pub fn frame(&mut self, canvas: &Canvas, delay_cs: u16) {
        assert_eq!((canvas.width, canvas.height), (self.width, self.height));
        self.bytes.extend_from_slice(&[0x21, 0xF9, 0x04, 0x00]);
        self.bytes.extend_from_slice(&delay_cs.to_le_bytes());
        self.bytes
            .extend_from_slice(&[0x00, 0x00, 0x2C, 0, 0, 0, 0]);
        self.bytes
            .extend_from_slice(&(self.width as u16).to_le_bytes());
        self.bytes
            .extend_from_slice(&(self.height as u16).to_le_bytes());
        self.bytes.extend_from_slice(&[0x00, 0x08]);
        let (mut data, mut acc, mut nbits) = (Vec::new(), 0u32, 0u32);
        let mut emit = |code: u32, data: &mut Vec<u8>| {
            acc |= code << nbits;
            nbits += 9;
            while nbits >= 8 {
                data.push(acc as u8);
                acc >>= 8;
                nbits -= 8;
            }
        };
        for (i, p) in canvas.pixels.iter().enumerate() {
            if i % 250 == 0 {
                emit(256, &mut data);
            }
            let q = |c: u8| (u32::from(c) + 25) / 51;
            emit(q(p[0]) * 36 + q(p[1]) * 6 + q(p[2]), &mut data);
        }
        emit(257, &mut data);
        if nbits > 0 {
            data.push(acc as u8);
        }
        for chunk in data.chunks(255) {
            self.bytes.push(chunk.len() as u8);
            self.bytes.extend_from_slice(chunk);
        }
        self.bytes.push(0);
    }

    pub fn save(mut self, path: &Path) -> std::io::Result<()> {
        self.bytes.push(0x3B);
        if let Some(dir) = path.parent() {
            std::fs::create_dir_all(dir)?;
        }
        std::fs::write(path, self.bytes)
    }
}
