#!/usr/bin/env bash
# Installs the TOYRT add-on (addon/render_toyrt/ plus the built native module) into Blender's
# user add-ons folder and enables it in the user's preferences.
#
# Every step is skipped when it has nothing to do, so a second run takes a fraction of a second:
#   - Blender's folders are asked from Blender once and cached in build/ (keyed on the
#     environment that decides them: HOME, XDG_CONFIG_HOME, BLENDER_USER_*, the blender binary);
#   - the files are copied only when their content hashes differ from the installed ones';
#   - the add-on is enabled (and the preferences saved) once, then a stamp is kept while
#     userpref.blend exists.
# Env: BLENDER (default: blender), BUILD_DIR (default: build).
set -euo pipefail
cd "$(dirname "$0")/.."

BLENDER=${BLENDER:-blender}
BUILD_DIR=${BUILD_DIR:-build}
ADDON=render_toyrt
SRC=addon/$ADDON
mkdir -p "$BUILD_DIR"

key=$(printf '%s|' "$HOME" "${XDG_CONFIG_HOME:-}" "${BLENDER_USER_CONFIG:-}" \
        "${BLENDER_USER_SCRIPTS:-}" "$(command -v "$BLENDER")" | md5sum | cut -c1-12)
paths_cache=$BUILD_DIR/blender-paths-$key.txt
enabled_stamp=$BUILD_DIR/.stamp-addon-enabled-$key

# --- 1. Blender's user folders (asked once) ------------------------------------------------------
if [[ ! -s $paths_cache ]] || ! grep -q '^TOYRT_PY=' "$paths_cache"; then
  echo "addon: asking Blender for its user folders"
  out=$("$BLENDER" -b --factory-startup --python-exit-code 1 --python-expr \
"import bpy, sys
print('TOYRT_ADDONS_DIR=' + bpy.utils.user_resource('SCRIPTS', path='addons'))
print('TOYRT_CONFIG_DIR=' + bpy.utils.user_resource('CONFIG'))
print('TOYRT_PY=%d.%d' % sys.version_info[:2])" 2>&1) || { echo "$out" >&2; exit 1; }
  grep -E '^TOYRT_((ADDONS|CONFIG)_DIR=/|PY=)' <<<"$out" > "$paths_cache.tmp" || true
  if [[ $(wc -l < "$paths_cache.tmp") -ne 3 ]]; then
    echo "$out" >&2; echo "addon: could not read Blender's user folders" >&2; rm -f "$paths_cache.tmp"; exit 1
  fi
  mv "$paths_cache.tmp" "$paths_cache"
fi
ADDONS_DIR=$(sed -n 's/^TOYRT_ADDONS_DIR=//p' "$paths_cache")
CONFIG_DIR=$(sed -n 's/^TOYRT_CONFIG_DIR=//p' "$paths_cache")
DEST=$ADDONS_DIR/$ADDON

# --- 2. copy the add-on and the native module when they changed ----------------------------------
shopt -s nullglob
modules=("$BUILD_DIR"/python/toyrt*.so)
shopt -u nullglob
if ((${#modules[@]} != 1)); then
  echo "addon: expected exactly one $BUILD_DIR/python/toyrt*.so, found ${#modules[@]} (build it first: make setup)" >&2
  exit 1
fi
# The add-on's files as "sha256  relative-path" lines, sorted; the same for what is installed, so
# a changed, added or deleted file on either side (even by hand) triggers a fresh copy.
manifest() {  # manifest DIR [EXTRA_FILE]
  { (cd "$1" && find . -type f ! -path '*/__pycache__/*' ! -name '*.pyc' -print0 | sort -z \
       | xargs -0r sha256sum)
    [[ -z ${2:-} ]] || printf '%s  ./%s\n' "$(sha256sum < "$2" | cut -c1-64)" "$(basename "$2")"
  } | sort -k2
}
want=$(manifest "$SRC" "${modules[0]}")
have=""
if [[ -d $DEST ]]; then have=$(manifest "$DEST" | grep -v '  \./vendor/' || true); fi
if [[ "$want" == "$have" ]]; then
  echo "addon: $DEST is up to date"
else
  echo "addon: installing into $DEST"
  mkdir -p "$ADDONS_DIR"
  # Assemble beside the target, then swap it in: a Blender that has the old module loaded keeps its
  # (unlinked) file instead of seeing it overwritten in place
  # (the hidden temporary folder is not scanned as an add-on).
  tmp=$ADDONS_DIR/.$ADDON.tmp.$$
  rm -rf "$tmp"; mkdir -p "$tmp"
  cp -a "$SRC"/. "$tmp"/
  find "$tmp" \( -name __pycache__ -o -name '*.pyc' \) -prune -exec rm -rf {} +
  cp -p "${modules[0]}" "$tmp"/
  rm -rf "$DEST"
  mv "$tmp" "$DEST"
fi

# --- 2b. Open Image Denoise for the Denoise setting: Debian's Blender runs the system Python, which
# has no pyoidn (and is externally managed), so it goes into the add-on's vendor/ folder as in the
# legacy zip (scripts/vendor-pyoidn.py; kept in $BUILD_DIR/vendor, copied when its stamp differs).
VENDOR_PY=${VENDOR_PY:-.venv/bin/python}
py_version=$(sed -n 's/^TOYRT_PY=//p' "$paths_cache")
"$VENDOR_PY" scripts/vendor-pyoidn.py --target "$BUILD_DIR/vendor" --python "$py_version"
if ! cmp -s "$BUILD_DIR/vendor/VENDORED.txt" "$DEST/vendor/VENDORED.txt"; then
  rm -rf "$DEST/vendor" "$DEST/.vendor.tmp"
  cp -a "$BUILD_DIR/vendor" "$DEST/.vendor.tmp"
  mv "$DEST/.vendor.tmp" "$DEST/vendor"
  echo "addon: Open Image Denoise (pyoidn $py_version) vendored into $DEST/vendor"
fi

# --- 3. enable it in the user's preferences, once --------------------------------------------------
if [[ -f $enabled_stamp && -f $CONFIG_DIR/userpref.blend ]]; then
  echo "addon: $ADDON already enabled in $CONFIG_DIR/userpref.blend"
  exit 0
fi
echo "addon: enabling $ADDON and saving the user preferences"
# No --factory-startup here: the user's existing preferences are loaded, so saving keeps them.
out=$("$BLENDER" -b --python-exit-code 1 --python-expr \
"import addon_utils, bpy
mod = addon_utils.enable('$ADDON', default_set=True, persistent=True, handle_error=None)
assert mod is not None, 'addon_utils.enable returned None'
bpy.ops.wm.save_userpref()
print('TOYRT_ENABLED_OK')" 2>&1) || { echo "$out" >&2; echo "addon: enabling failed" >&2; exit 1; }
grep -q '^TOYRT_ENABLED_OK$' <<<"$out" || { echo "$out" >&2; echo "addon: enabling failed" >&2; exit 1; }

# Check in a fresh Blender that the preference stuck.
out=$("$BLENDER" -b --python-exit-code 1 --python-expr \
"import bpy, sys
ok = '$ADDON' in bpy.context.preferences.addons
print('TOYRT_ENABLED_CHECK=' + str(ok))
sys.exit(0 if ok else 1)" 2>&1) || { echo "$out" >&2; echo "addon: $ADDON is not enabled after saving the preferences" >&2; exit 1; }
printf '%s\n' "$CONFIG_DIR" > "$enabled_stamp"
echo "addon: $ADDON enabled (saved to $CONFIG_DIR/userpref.blend)"
