# test_oom makes the library's allocations fail one at a time: its
# executable routes malloc, calloc and realloc through wrappers of its own.
target_link_options(test_oom PRIVATE "LINKER:--wrap=malloc,--wrap=calloc,--wrap=realloc")
