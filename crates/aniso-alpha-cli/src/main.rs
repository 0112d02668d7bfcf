//! `aniso-alpha`: command-line front end of the aniso-alpha library.
fn main() {
    println!("aniso-alpha");
}
