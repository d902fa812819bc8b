# Sourced by .ci/run and .ci/lib_alone.sh: `stage NAME` prints a stage line
# with the wall time since the script started and the CPU time (user +
# system) of everything it has run so far (the shell's reaped children), and
# the load average: on a shared machine the wall time follows the load, the
# CPU time much less. STAGE_PREFIX, if set, starts each line.
stage_start=$(date +%s)
stage_cpu_file=$(mktemp)
trap 'rm -f "$stage_cpu_file"' EXIT
stage() {
    times > "$stage_cpu_file"  # in this shell: its children's CPU so far
    local cpu
    cpu=$(awk 'NR == 2 { split($1, u, /[ms]/); split($2, s, /[ms]/);
        printf "%d", 60 * (u[1] + s[1]) + u[2] + s[2] }' "$stage_cpu_file")
    echo "== ${STAGE_PREFIX:-}$1 ($(( $(date +%s) - stage_start )) s, CPU $cpu s, load $(cut -d' ' -f1 /proc/loadavg))"
}
