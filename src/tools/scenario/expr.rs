//! Closed forms in scenario files: arithmetic on `t`, `g` and `pi`.
//!
//! Written here rather than taken from a crate: the maintained evaluators either carry a
//! copyleft licence (evalexpr ≥ 12 is AGPL-3.0) or pull `regex` into every build of the
//! library (exmex), for a grammar of five operators and eight functions. The grammar:
//!
//! ```text
//! expr  = term (('+' | '-') term)*
//! term  = unary (('*' | '/') unary)*
//! unary = '-' unary | power
//! power = atom ('^' unary)?          right-associative, binds tighter than unary minus
//! atom  = number | name | name '(' expr ')' | '(' expr ')'
//! ```
//!
//! It is parsed once, when the file is read, and evaluated in f64 at every check.

/// A parsed expression.
#[derive(Debug, Clone, PartialEq)]
pub enum Expr {
    /// A number.
    Num(f64),
    /// A variable: `t` (s), `g` (m/s²).
    Var(Var),
    /// −e.
    Neg(Box<Expr>),
    /// A binary operation.
    Bin(Op, Box<Expr>, Box<Expr>),
    /// A function of one argument.
    Call(Func, Box<Expr>),
}

/// The variables an expression may read.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Var {
    /// Time since the start (s).
    T,
    /// The magnitude of gravity at the start (m/s²).
    G,
}

/// Binary operators.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Op {
    /// +
    Add,
    /// −
    Sub,
    /// ×
    Mul,
    /// ÷
    Div,
    /// ^
    Pow,
}

/// Functions.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Func {
    /// √
    Sqrt,
    /// sin (rad)
    Sin,
    /// cos (rad)
    Cos,
    /// tan (rad)
    Tan,
    /// eˣ
    Exp,
    /// natural log
    Ln,
    /// |x|
    Abs,
}

impl Expr {
    /// Parses `text`; the error says what and where (a 1-based column).
    ///
    /// # Errors
    /// A message naming the column of the first unexpected character.
    pub fn parse(text: &str) -> Result<Expr, String> {
        let mut p = Parser {
            s: text.as_bytes(),
            i: 0,
            depth: 0,
            operators: 0,
        };
        let e = p.expr()?;
        p.skip_ws();
        if p.i < p.s.len() {
            return Err(p.unexpected());
        }
        Ok(e)
    }

    /// The value at time `t` (s) under gravity `g` (m/s²).
    #[must_use]
    pub fn eval(&self, t: f64, g: f64) -> f64 {
        match self {
            Expr::Num(x) => *x,
            Expr::Var(Var::T) => t,
            Expr::Var(Var::G) => g,
            Expr::Neg(e) => -e.eval(t, g),
            Expr::Bin(op, a, b) => {
                let (a, b) = (a.eval(t, g), b.eval(t, g));
                match op {
                    Op::Add => a + b,
                    Op::Sub => a - b,
                    Op::Mul => a * b,
                    Op::Div => a / b,
                    Op::Pow => a.powf(b),
                }
            }
            Expr::Call(f, e) => {
                let x = e.eval(t, g);
                match f {
                    Func::Sqrt => x.sqrt(),
                    Func::Sin => x.sin(),
                    Func::Cos => x.cos(),
                    Func::Tan => x.tan(),
                    Func::Exp => x.exp(),
                    Func::Ln => x.ln(),
                    Func::Abs => x.abs(),
                }
            }
        }
    }
}

/// How deep an expression may nest (parentheses, signs, powers, calls): a parser that
/// recursed 100,000 parentheses deep overflowed the stack and aborted the process.
pub const MAX_DEPTH: u32 = 256;

/// How many operators an expression may hold: evaluating and dropping a chain of 100,000
/// additions recurses as deep as the chain is long.
pub const MAX_OPERATORS: u32 = 4096;

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
    depth: u32,
    operators: u32,
}

impl Parser<'_> {
    fn skip_ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }

    fn peek(&mut self) -> Option<u8> {
        self.skip_ws();
        self.s.get(self.i).copied()
    }

    fn unexpected(&self) -> String {
        match self.s.get(self.i) {
            Some(&c) => format!("unexpected '{}' at column {}", c as char, self.i + 1),
            None => format!("unexpected end at column {}", self.i + 1),
        }
    }

    /// Counts one more operator, refusing past [`MAX_OPERATORS`].
    fn operator(&mut self) -> Result<(), String> {
        self.operators += 1;
        if self.operators > MAX_OPERATORS {
            return Err(format!(
                "more than {MAX_OPERATORS} operators (column {})",
                self.i + 1
            ));
        }
        Ok(())
    }

    fn expr(&mut self) -> Result<Expr, String> {
        let mut e = self.term()?;
        while let Some(c @ (b'+' | b'-')) = self.peek() {
            self.operator()?;
            self.i += 1;
            let op = if c == b'+' { Op::Add } else { Op::Sub };
            e = Expr::Bin(op, Box::new(e), Box::new(self.term()?));
        }
        Ok(e)
    }

    fn term(&mut self) -> Result<Expr, String> {
        let mut e = self.unary()?;
        while let Some(c @ (b'*' | b'/')) = self.peek() {
            self.operator()?;
            self.i += 1;
            let op = if c == b'*' { Op::Mul } else { Op::Div };
            e = Expr::Bin(op, Box::new(e), Box::new(self.unary()?));
        }
        Ok(e)
    }

    /// Every recursion of the parser passes here: the nesting is counted and bounded.
    fn unary(&mut self) -> Result<Expr, String> {
        self.depth += 1;
        if self.depth > MAX_DEPTH {
            return Err(format!(
                "nested deeper than {MAX_DEPTH} at column {}",
                self.i + 1
            ));
        }
        let e = self.signed();
        self.depth -= 1;
        e
    }

    fn signed(&mut self) -> Result<Expr, String> {
        if self.peek() == Some(b'-') {
            self.operator()?;
            self.i += 1;
            return Ok(Expr::Neg(Box::new(self.unary()?)));
        }
        let base = self.atom()?;
        if self.peek() == Some(b'^') {
            self.operator()?;
            self.i += 1;
            // −t^2 is −(t²) and 2^-1 is ½: the exponent is a unary.
            return Ok(Expr::Bin(Op::Pow, Box::new(base), Box::new(self.unary()?)));
        }
        Ok(base)
    }

    fn atom(&mut self) -> Result<Expr, String> {
        match self.peek() {
            Some(b'(') => {
                self.i += 1;
                let e = self.expr()?;
                self.close()?;
                Ok(e)
            }
            Some(c) if c.is_ascii_digit() || c == b'.' => self.number(),
            Some(c) if c.is_ascii_alphabetic() => self.name(),
            _ => Err(self.unexpected()),
        }
    }

    fn close(&mut self) -> Result<(), String> {
        if self.peek() == Some(b')') {
            self.i += 1;
            Ok(())
        } else {
            Err(self.unexpected())
        }
    }

    fn number(&mut self) -> Result<Expr, String> {
        let start = self.i;
        while self.i < self.s.len() && (self.s[self.i].is_ascii_digit() || self.s[self.i] == b'.') {
            self.i += 1;
        }
        // An exponent: 1e-3, 2.5E4.
        if self.i < self.s.len() && matches!(self.s[self.i], b'e' | b'E') {
            let save = self.i;
            self.i += 1;
            if self.i < self.s.len() && matches!(self.s[self.i], b'+' | b'-') {
                self.i += 1;
            }
            if self.i < self.s.len() && self.s[self.i].is_ascii_digit() {
                while self.i < self.s.len() && self.s[self.i].is_ascii_digit() {
                    self.i += 1;
                }
            } else {
                self.i = save;
            }
        }
        let text = core::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        text.parse::<f64>()
            .map(Expr::Num)
            .map_err(|_| format!("bad number '{text}' at column {}", start + 1))
    }

    fn name(&mut self) -> Result<Expr, String> {
        let start = self.i;
        while self.i < self.s.len()
            && (self.s[self.i].is_ascii_alphanumeric() || self.s[self.i] == b'_')
        {
            self.i += 1;
        }
        let name = core::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        let func = match name {
            "t" => return Ok(Expr::Var(Var::T)),
            "g" => return Ok(Expr::Var(Var::G)),
            "pi" => return Ok(Expr::Num(core::f64::consts::PI)),
            "sqrt" => Func::Sqrt,
            "sin" => Func::Sin,
            "cos" => Func::Cos,
            "tan" => Func::Tan,
            "exp" => Func::Exp,
            "ln" => Func::Ln,
            "abs" => Func::Abs,
            _ => {
                return Err(format!(
                    "unknown name '{name}' at column {} (t, g, pi, sqrt, sin, cos, tan, exp, ln, abs)",
                    start + 1
                ));
            }
        };
        if self.peek() != Some(b'(') {
            return Err(format!("{name} needs parentheses at column {}", self.i + 1));
        }
        self.i += 1;
        let arg = self.expr()?;
        self.close()?;
        Ok(Expr::Call(func, Box::new(arg)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(text: &str, t: f64) -> f64 {
        Expr::parse(text).unwrap().eval(t, 9.81)
    }

    #[test]
    fn precedence_and_associativity_follow_the_usual_rules() {
        assert_eq!(at("1 + 2 * 3", 0.0), 7.0);
        assert_eq!(at("(1 + 2) * 3", 0.0), 9.0);
        assert_eq!(at("2 ^ 3 ^ 2", 0.0), 512.0);
        assert_eq!(at("-t^2", 3.0), -9.0);
        assert_eq!(at("2^-1", 0.0), 0.5);
        assert_eq!(at("10 - 8 - 1", 0.0), 1.0);
        assert_eq!(at("8 / 4 / 2", 0.0), 1.0);
        assert_eq!(at("1e-3 * 2E3", 0.0), 2.0);
        assert!((at("10 - g*t^2/2", 1.0) - 5.095).abs() < 1e-12);
        assert!((at("cos(2*pi*t)", 0.5) + 1.0).abs() < 1e-12);
        assert!((at("sqrt(abs(-16)) + ln(exp(2))", 0.0) - 6.0).abs() < 1e-12);
    }

    #[test]
    fn bad_expressions_name_the_column() {
        assert_eq!(
            Expr::parse("1 +").unwrap_err(),
            "unexpected end at column 4"
        );
        assert!(
            Expr::parse("2 * x")
                .unwrap_err()
                .contains("unknown name 'x' at column 5")
        );
        assert!(Expr::parse("(1 + 2").unwrap_err().contains("column 7"));
        assert!(Expr::parse("sin t").unwrap_err().contains("parentheses"));
        assert!(Expr::parse("1 2").unwrap_err().contains("'2' at column 3"));
        assert!(Expr::parse("1..2").unwrap_err().contains("bad number"));
    }
}
