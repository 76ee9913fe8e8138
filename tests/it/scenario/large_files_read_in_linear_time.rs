//! Regression: reading a scenario found each entry's line by scanning the file from the top,
//! so reading was quadratic in its size (5,000 entries 0.54 s, 40,000 entries 22–45 s). A
//! file of 100,000 entries now reads in well under a second in a release build (about
//! 0.2 s for 40,000 on the CI machine); quadratically it would take over ten minutes, past
//! any patience. Errors still name the right line.

use hooke::tools::scenario::Scenario;

fn particles(n: usize, bad_at: Option<usize>) -> String {
    let mut text = String::from("(\n    duration: 0.1,\n    entities: [\n");
    for i in 0..n {
        let x = if Some(i) == bad_at { "oops" } else { "0.0" };
        text.push_str(&format!(
            "        (name: \"p{i}\", spawn: Particle(at: ({x}, {}, 0.0))),\n",
            i as f32 * 0.01
        ));
    }
    text.push_str("    ],\n    expect: [],\n)\n");
    text
}

#[test]
fn a_hundred_thousand_entries_read_and_errors_name_their_line() {
    let n = 100_000;
    let s = Scenario::from_str(&particles(n, None), "big.ron").expect("reads");
    assert_eq!(s.steps(), 6);
    // Entry i sits on line i + 4; a bad value near the end is reported there.
    let e = Scenario::from_str(&particles(n, Some(n - 7)), "big.ron").expect_err("bad value");
    assert_eq!(e.line, n - 7 + 4, "{e}");
}
