#!/usr/bin/env bash
# Installs and builds what the engines need, idempotently (called by tools/setup.sh --engines):
#   1. Debian's LIGGGHTS 3.8 and OpenFOAM v1912 (+ OpenMPI headers, a compiler);
#   2. OpenFOAM's headers and wmake from Debian's source package (the binary packages have
#      none), kept in $COLLHEAT_CACHE (default /var/cache/collheat) so that every checkout
#      on this machine shares them;
#   3. the project's OpenFOAM solver (plugins/openfoam/collheatFoam) and LIGGGHTS helper
#      library (plugins/liggghts), built into .setup/ of this checkout.
# Each step is skipped when its result is present; a second run only checks and returns.
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
cd "$top"
export DEBIAN_FRONTEND=noninteractive
cache=${COLLHEAT_CACHE:-/var/cache/collheat}
out=$top/.setup
sudo=""
[ "$(id -u)" = 0 ] || sudo=sudo

packages=(liggghts libliggghts-dev liggghts-doc openfoam libopenfoam openfoam-examples
          libopenmpi-dev openmpi-bin python3-mpi4py g++ make flex bzip2)
missing=()
for p in "${packages[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "setup_engines: installing Debian packages: ${missing[*]}"
    $sudo apt-get update -q
    $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

# OpenFOAM's headers and wmake: Debian's source package, without tutorials and doc.
foam_version=1912.200626
foam_src=$cache/OpenFOAM-v1912
if [ ! -f "$foam_src/.collheat-ready" ]; then
    echo "setup_engines: preparing OpenFOAM headers from Debian's source package in $foam_src"
    src_list=/etc/apt/sources.list.d/collheat-deb-src.sources
    if ! apt-get source --print-uris openfoam >/dev/null 2>&1; then
        # A deb-src twin of Debian's main entry: the first stanza of debian.sources, or
        # the deb lines of a classic sources.list.
        if [ -f /etc/apt/sources.list.d/debian.sources ]; then
            awk 'BEGIN{RS=""} NR==1{print}' /etc/apt/sources.list.d/debian.sources \
                | sed 's/^Types:.*/Types: deb-src/' | $sudo tee "$src_list" >/dev/null
        else
            src_list=/etc/apt/sources.list.d/collheat-deb-src.list
            sed -n 's/^deb /deb-src /p' /etc/apt/sources.list | $sudo tee "$src_list" >/dev/null
        fi
        $sudo apt-get update -q
    fi
    dl=$cache/download
    $sudo mkdir -p "$dl"
    (cd "$dl" && $sudo apt-get source --download-only -q "openfoam=$foam_version-1")
    tarball=$dl/openfoam_$foam_version.orig.tar.bz2
    want=$(awk '/^Checksums-Sha256:/{f=1;next} /^[A-Z]/{f=0} f && $3 ~ /orig.tar.bz2$/ {print $1}' \
           "$dl/openfoam_$foam_version-1.dsc")
    echo "$want  $tarball" | sha256sum -c --quiet
    $sudo rm -rf "$foam_src" "$cache/extract"
    $sudo mkdir -p "$cache/extract"
    $sudo tar -xjf "$tarball" -C "$cache/extract" \
        --exclude='*/tutorials' --exclude='*/doc' --exclude='*/.git*'
    $sudo mv "$cache/extract"/* "$foam_src"
    $sudo rmdir "$cache/extract"
    (
        set +eu
        export USER=${USER:-root}
        . "$foam_src/etc/bashrc"
        set -e
        "$WM_DIR/src/Allmake" >/dev/null
        wmakeLnIncludeAll -j2 "$WM_PROJECT_DIR/src" >/dev/null
    )
    $sudo touch "$foam_src/.collheat-ready"
fi

# The project's compiled extensions, each rebuilt when its sources change.
mkdir -p "$out/bin" "$out/lib"
changed() {  # changed NAME DIR RESULT: true when DIR's sources differ from the last build
    local stamp=$out/.$1.stamp
    local want
    want=$(find "$2" -type f ! -path '*/Make/linux*' ! -path '*/lnInclude/*' -print0 \
           | sort -z | xargs -0 sha256sum | sha256sum | cut -d' ' -f1)
    [ "$(cat "$stamp" 2>/dev/null)" != "$want" ] || [ ! -e "$3" ] || return 1
    echo "$want" > "$stamp.new"
}
done_build() { mv "$out/.$1.stamp.new" "$out/.$1.stamp"; }

helper=$out/lib/libcollheat_liggghts.so
if changed liggghts plugins/liggghts "$helper"; then
    echo "setup_engines: compiling plugins/liggghts"
    flags=(-O2 -fPIC -DOMPI_SKIP_MPICXX -I/usr/include/liggghts
           $(pkg-config --cflags ompi 2>/dev/null || echo -I/usr/lib/x86_64-linux-gnu/openmpi/include))
    objects=()
    pids=()
    for src in plugins/liggghts/*.cpp; do            # each source on a core of its own, then linked
        obj=$out/lib/$(basename "${src%.cpp}").o
        g++ "${flags[@]}" -c "$src" -o "$obj" & pids+=($!)
        objects+=("$obj")
    done
    for pid in "${pids[@]}"; do wait "$pid"; done
    g++ -shared "${objects[@]}" -o "$helper" -Wl,--no-as-needed -lliggghts -lmpi
    rm -f "${objects[@]}"
    done_build liggghts
fi

solver=$out/bin/collheatFoam
if changed openfoam plugins/openfoam "$solver"; then
    echo "setup_engines: compiling plugins/openfoam/collheatFoam (about 30 s)"
    (
        set +eu
        export USER=${USER:-root}
        . "$foam_src/etc/bashrc"
        set -e
        export COLLHEAT_BIN=$out/bin
        cd plugins/openfoam/collheatFoam
        WM_NCOMPPROCS=2 wmake > "$out/log.wmake" 2>&1 || { tail -30 "$out/log.wmake" >&2; exit 1; }
    )
    done_build openfoam
fi
echo "setup_engines: ready (solver $solver, helper $helper)"
