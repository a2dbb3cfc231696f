# Sourced by check and report: the QEMU board named by $1 (m4 or m33).
#   target    the Rust target, which selects the memory map (build.rs)
#   machine   QEMU's board; cpu, core: its processor
#   elf       the firmware as built for it (release)
# and qemu ELF: runs an ELF on the board with semihosting, -icount shift=0, timeout 300 s.
case "${1:-}" in
  m4) target=thumbv7em-none-eabihf machine=mps2-an386 cpu=cortex-m4 core=Cortex-M4F ;;
  m33) target=thumbv8m.main-none-eabihf machine=mps2-an505 cpu=cortex-m33 core=Cortex-M33F ;;
  *)
    echo "usage: $(basename "$0") m4|m33 [options] (or boards/qemu-m4/$(basename "$0"), boards/qemu-m33/$(basename "$0"))" >&2
    exit 2
    ;;
esac
board=$1
elf=target/$target/release/qemu-firmware

qemu() {
  timeout 300 qemu-system-arm -machine "$machine" -cpu "$cpu" -nographic -monitor none \
    -serial none -semihosting-config enable=on,target=native -icount shift=0 -kernel "$1"
}
