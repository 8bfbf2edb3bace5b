//! `haptic2d scenes`: lists the built-in scenes.

use haptic2d::scene::BUILTIN;

/// Prints the built-in scenes with their descriptions.
pub fn run() -> Result<(), String> {
    println!(
        "Built-in scenes (use the name wherever a SCENE is expected; `pile:N` gives N boxes, 25 per row, or 40 rows in a wider container above 1000):"
    );
    for (name, desc, _) in BUILTIN {
        println!("  {name:<20} {desc}");
    }
    println!("\nScene files: see docs/SCENES.md; the built-in ones are in scenes/.");
    Ok(())
}
