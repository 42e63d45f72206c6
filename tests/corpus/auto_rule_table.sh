#!/bin/sh
# A game too large for straight-line rules: `auto` must write them as a table
# (psc --verbose says so) and the replay must pass, every state as recorded.
#   auto_rule_table.sh PSC CASE.json
out=$("$1" replay "$2" --verbose 2>&1)
status=$?
printf '%s\n' "$out" | grep -v warning
[ "$status" -eq 0 ] || exit 1
printf '%s\n' "$out" | grep -q 'rules as a table: their code would be' || { echo "auto did not choose the table form"; exit 1; }
printf '%s\n' "$out" | grep -q '^PASS' || exit 1
