# Sourced by tools/run, tools/test, tools/results and tools/screenshots: the build-cache settings every command
# shares, and the choice of Vulkan driver. A build cache outside the clone is reused when one exists, so repeated
# CI runs stay fast.
if [ -z "${CARGO_TARGET_DIR:-}" ] && [ -d /var/cache/riverplanet-target ]; then
  export CARGO_TARGET_DIR=/var/cache/riverplanet-target
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"

# The tests, the published results and the pictures run on lavapipe, so that they mean the same on every machine,
# unless the caller chose a driver (VK_LOADER_DRIVERS_SELECT) or a device (RIVERPLANET_ADAPTER). tools/run does not
# call this: riverplanet itself takes the best device present (a discrete GPU first, lavapipe when there is none).
use_lavapipe() {
  if [ -z "${RIVERPLANET_ADAPTER:-}" ]; then
    : "${VK_LOADER_DRIVERS_SELECT:=*lvp*}"
    export VK_LOADER_DRIVERS_SELECT
  fi
}
