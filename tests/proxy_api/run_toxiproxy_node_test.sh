#!/usr/bin/env bash
# Installs the released Toxiproxy Node client from the npm registry into
# NPM_DIR (once; a later run reuses it) and runs toxiproxy_node_test.js
# against hil. Exits 77 (ctest's skip) when the registry cannot be reached.
#
# Usage: run_toxiproxy_node_test.sh NODE NPM HIL_BINARY NPM_DIR
set -u
node=$1 npm=$2 hil=$3 npm_dir=$4
client=toxiproxy-node-client
version=4.1.0
here=$(cd "$(dirname "$0")" && pwd)

installed=$npm_dir/node_modules/$client/package.json
if ! grep -q "\"version\": \"$version\"" "$installed" 2>/dev/null; then
  mkdir -p "$npm_dir"
  log=$npm_dir/npm-install.log
  if ! "$npm" install --prefix "$npm_dir" --no-audit --no-fund --no-save \
       --fetch-retries=1 --fetch-timeout=30000 "$client@$version" >"$log" 2>&1; then
    cat "$log"
    if grep -Eqi 'E(NOTFOUND|CONNREFUSED|CONNRESET|TIMEDOUT|AI_AGAIN|NETUNREACH|HOSTUNREACH)|EPROXY|network|socket hang up|ERR_SOCKET' "$log"; then
      echo "SKIP: the npm registry ($("$npm" config get registry 2>/dev/null)) was not reachable, so $client@$version could not be installed"
      exit 77
    fi
    echo "FAIL: npm install $client@$version failed (see above)"
    exit 1
  fi
fi
echo "$client $(sed -n 's/.*"version": "\(.*\)".*/\1/p' "$installed" | head -1) from $npm_dir"
NODE_PATH=$npm_dir/node_modules exec "$node" "$here/toxiproxy_node_test.js" "$hil"
