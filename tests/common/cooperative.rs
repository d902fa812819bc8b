
#[test]
#[ignore]
fn print_domino_t_values() {
    for k in 0..11 {
        let sh = 0.1 + 0.05 * k as f64;
        println!("{sh:.2} {:.4} {:.4}", cooperative_speed(0.08, 0.0096, sh * 0.08, 0.0), cooperative_speed(0.08, 0.0096, sh * 0.08, 0.15));
    }
}
