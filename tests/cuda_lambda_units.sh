#!/usr/bin/env bash
# Fails when two CUDA translation units define the same extended __host__ __device__ lambda.
#
# nvcc keeps the function pointers behind such a lambda (__nv_hdl_helper<...>::fp_copier) in an
# anonymous namespace, one copy per unit, while parallel_for<that lambda> is an ordinary inline
# template that the linker keeps from one unit only. A lambda written in a non-template function
# has the same type in every unit that compiles it, so a program can make the lambda in one unit
# and copy it with the other unit's copier, which that unit never set: a call through a null
# pointer (simulation/instantiate_cuda.cu says how it showed). No GPU is needed to see it: the
# symbol tables tell.
#
# Usage: tests/cuda_lambda_units.sh FILE...   object files or static libraries (each archive
# member is a unit). Exit 0 when no lambda is defined in two units, 1 (listing them) otherwise.
set -euo pipefail
[[ $# -gt 0 ]] || { echo "usage: $0 OBJECT_OR_ARCHIVE..." >&2; exit 2; }
for f in "$@"; do
  [[ -r "$f" ]] || { echo "cuda_lambda_units: cannot read $f" >&2; exit 2; }
done
# nm -A prefixes each line with its unit: "lib.a:member.o:ADDRESS TYPE NAME" or "file.o:...".
listing=$(nm -A "$@" | awk '$NF ~ /__nv_hdl_helper.*fp_copier/ { unit = $1; sub(/:[0-9a-f]+$/, "", unit); print unit "\t" $NF }')
units=$(cut -f1 <<<"$listing" | sort -u | grep -c . || true)
lambdas=$(cut -f2 <<<"$listing" | sort -u | grep -c . || true)
# None at all means the symbols are no longer named as this script expects (another nvcc): a check
# that finds nothing to compare must not pass.
((lambdas > 0)) || { echo "cuda_lambda_units: no __nv_hdl_helper<...>::fp_copier symbol in $*; has nvcc renamed them?"; exit 1; }
shared=$(awk -F'\t' '{ seen[$2] = seen[$2] " " $1; count[$2]++ } END { for (k in count) if (count[k] > 1) print k "\t" seen[k] }' <<<"$listing")
if [[ -n "$shared" ]]; then
  echo "cuda_lambda_units: $(grep -c . <<<"$shared") extended lambdas are defined in more than one CUDA unit:"
  shown=0
  while IFS=$'\t' read -r name where; do
    ((++shown <= 10)) || continue
    echo "  $(c++filt <<<"$name" | cut -c1-160) ...; in:$where"
  done <<<"$shared"
  echo "Instantiate every algorithm that uses them in one unit (simulation/instantiate_cuda.cu)."
  exit 1
fi
echo "cuda_lambda_units: $lambdas extended lambdas in $units units, none in two"
