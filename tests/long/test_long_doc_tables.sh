#!/usr/bin/env bash
# test_long_doc_tables.sh -- the long tier of tests/docs/test_doc_tables.sh:
# every table of docs/ that takes minutes to rerun (Table 2 of decimation,
# the selection table, the optimisers against the optimum) and the cheap
# ones, compared cell by cell with what this binary gives.
TT_DOC_TIER=long exec bash "$(dirname "${BASH_SOURCE[0]}")/../docs/test_doc_tables.sh"
