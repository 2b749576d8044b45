# test_oom makes the library's allocations fail one at a time, and its threads
# fail to start: its executable routes malloc, calloc, realloc and
# pthread_create (and mmap, to fail a file's mapping) through wrappers of its own.
target_link_options(test_oom PRIVATE "LINKER:--wrap=malloc,--wrap=calloc,--wrap=realloc,--wrap=pthread_create,--wrap=mmap")
