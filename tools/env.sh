# Sourced by tools/run and tools/test: the Vulkan driver and build-cache settings every command shares.
# Lavapipe is chosen explicitly unless the caller already chose a driver (a user with a GPU unsets it or sets
# RIVERPLANET_ADAPTER); a build cache outside the clone is reused when one exists, so repeated CI runs stay fast.
: "${VK_LOADER_DRIVERS_SELECT:=*lvp*}"
export VK_LOADER_DRIVERS_SELECT
if [ -z "${CARGO_TARGET_DIR:-}" ] && [ -d /var/cache/riverplanet-target ]; then
  export CARGO_TARGET_DIR=/var/cache/riverplanet-target
fi
export XDG_RUNTIME_DIR="${XDG_RUNTIME_DIR:-/tmp}"
