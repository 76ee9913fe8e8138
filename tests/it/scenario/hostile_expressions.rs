//! A closed form nested 100,000 parentheses deep overflowed the parser's stack and aborted
//! the process; a chain of 100,000 additions would overflow evaluating and dropping it. Both
//! are typed errors at load, naming the bound.

use hooke::tools::scenario::Scenario;

fn scenario_with(value: &str) -> String {
    format!(
        r#"(
        name: "hostile",
        duration: 0.1,
        entities: [(name: "p", spawn: Particle(at: (0, 1, 0)))],
        expect: [(check: ClosedForm(entity: "p", quantity: Y, value: "{value}", tolerance: 1.0))],
    )"#
    )
}

#[test]
fn deeply_nested_or_endless_closed_forms_are_refused_not_aborted() {
    let deep = format!("{}1{}", "(".repeat(100_000), ")".repeat(100_000));
    let signs = format!("{}1", "-".repeat(100_000));
    let chain = format!("1{}", "+1".repeat(100_000));
    for (what, value) in [
        ("parentheses", deep),
        ("signs", signs),
        ("additions", chain),
    ] {
        // On a thread with a small stack, as a test or a game's worker would be.
        let text = scenario_with(&value);
        let err = std::thread::Builder::new()
            .stack_size(256 * 1024)
            .spawn(move || Scenario::from_str(&text, "hostile.ron").map(|_| ()))
            .unwrap()
            .join()
            .expect("no stack overflow")
            .unwrap_err();
        let message = err.to_string();
        println!("{what}: {}", &message[..message.len().min(160)]);
        assert!(
            message.contains("deeper than") || message.contains("operators"),
            "{what}: {message}"
        );
    }
    // A sane closed form still reads.
    let fine = scenario_with("1 - 0.5*g*t^2 + ((2*t) - (-(t)))");
    assert!(Scenario::from_str(&fine, "fine.ron").is_ok());
}
