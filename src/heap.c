/* placeholder: being written this session */
typedef int tt_placeholder_heap;
