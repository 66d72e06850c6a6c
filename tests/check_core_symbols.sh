#!/bin/sh
# The core is plain C11 for a Cortex-M4: no heap, no stdio, no OS calls, libm only.
lib="$1"
[ -f "$lib" ] || { echo "core_symbols: no library at '$lib'" >&2; exit 2; }
bad=$(nm -u "$lib" | awk '{print $NF}' | sort -u |
      grep -E '^(malloc|calloc|realloc|free|printf|fprintf|sprintf|snprintf|vsnprintf|puts|fputs|fwrite|fopen|fclose|strtod|strtof|strtol|atof|atoi|sscanf|open|read|write|close|time|clock_gettime|gettimeofday|abort|exit)$')
if [ -n "$bad" ]; then
  echo "core_symbols: the core references forbidden functions:" $bad >&2
  exit 1
fi
echo "core_symbols: $(nm -u "$lib" | awk '{print $NF}' | sort -u | tr '\n' ' ')"
echo "1 passed, 0 failed"
