# Sourced by check and report: the QEMU board named by $1 (m4, m33 or m0).
#   target    the Rust target, which selects the memory map (build.rs)
#   machine   QEMU's board; cpu, core: its processor
#   reference the host's trace the device's must equal (make-assets): the f32 front-end's, or
#             for m0 the fixed-point front-end's (the runtime's `fixed` feature, which the
#             firmware turns on for thumbv6m-none-eabi)
#   budget_*  report's budgets: instructions per audio second, worst decision, RAM, code
#   elf       the firmware as built for it (release)
# and qemu ELF: runs an ELF on the board with semihosting, -icount shift=0, timeout 300 s.
reference=assets/trace.txt
budget_ips=6400000 budget_decision=50000 budget_ram=32768 budget_code=98304
case "${1:-}" in
  m4) target=thumbv7em-none-eabihf machine=mps2-an386 cpu=cortex-m4 core=Cortex-M4F ;;
  m33) target=thumbv8m.main-none-eabihf machine=mps2-an505 cpu=cortex-m33 core=Cortex-M33F ;;
  # ARMv6-M code (a Cortex-M0+, no FPU) on the M4's board: its core runs the ARMv6-M subset,
  # one instruction per instruction, and mps2-an386 has room for the blob.
  m0)
    target=thumbv6m-none-eabi machine=mps2-an386 cpu=cortex-m4 core="ARMv6-M (Cortex-M0+ code, no FPU)"
    reference=assets/trace-fixed.txt
    # Half of a 133 MHz RP2040 core (an instruction counted as a cycle).
    budget_ips=66500000 budget_decision=1000000 budget_ram=65536 budget_code=196608
    ;;
  *)
    echo "usage: $(basename "$0") m4|m33|m0 [options] (or boards/qemu-<board>/$(basename "$0"))" >&2
    exit 2
    ;;
esac
board=$1
elf=target/$target/release/qemu-firmware

# Panic locations carry source paths (the runtime's and a few of its dependencies'): the
# checkout and Cargo's home are remapped to fixed names, so the code size does not depend on
# where they are (it did by up to a hundred bytes per character of path). Cargo adds these
# flags to .cargo/config.toml's for the target.
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
cargo_home="${CARGO_HOME:-$HOME/.cargo}"
flags_var="CARGO_TARGET_$(tr 'a-z.-' 'A-Z__' <<<"$target")_RUSTFLAGS"
export "$flags_var=--remap-path-prefix=$root=/gesture --remap-path-prefix=$cargo_home=/cargo"

qemu() {
  timeout 300 qemu-system-arm -machine "$machine" -cpu "$cpu" -nographic -monitor none \
    -serial none -semihosting-config enable=on,target=native -icount shift=0 -kernel "$1"
}
