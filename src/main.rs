//! `frf`: the command-line front end. It only parses arguments and wires the crates.

fn main() {
    println!("frf");
}
