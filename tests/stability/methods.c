#include "methods.h"

#include <stdio.h>
#include <stdlib.h>

#include "builder.h"
#include "naive.h"

static void add(Method *methods, int capacity, int *count, Method m)
{
    if (*count >= capacity) {
        fprintf(stderr, "stability_methods: more than %d methods (at \"%s\")\n", capacity, m.name);
        exit(2);
    }
    methods[(*count)++] = m;
}

int stability_methods(Method *m, int capacity)
{
    int n = 0;
    PtrIsectTable c;
    ptr_isect_init_level(&c, PTR_CPU_NONE);
    PtrIsectTable naive = { .closest_hit = naive_closest_hit, .name = "naive" };

    add(m, capacity, &n, (Method){ "naive, t_min 1e-3", naive, 1e-3f, 0, 0 });
    add(m, capacity, &n, (Method){ "robust, t_min 1e-3", c, 1e-3f, 0, 0 });
    add(m, capacity, &n, (Method){ "robust, offset", c, 0.0f, 0, 0 });
    add(m, capacity, &n, (Method){ "huge in float", c, 0.0f, PTR_BUILD_RECENTRE, 0 });
    add(m, capacity, &n, (Method){ "ptr (c)", c, 0.0f, PTR_BUILD_DEFAULT, 1 });
    for (int l = PTR_CPU_SSE41; l <= (int)ptr_cpu_level(); l++) {
        PtrIsectTable t;
        ptr_isect_init_level(&t, (PtrCpuLevel)l);
        if (t.closest_hit == c.closest_hit)
            continue;
        static char names[PTR_CPU_LEVEL_COUNT][16];
        snprintf(names[l], sizeof names[l], "ptr (%s)", t.name);
        add(m, capacity, &n, (Method){ names[l], t, 0.0f, PTR_BUILD_DEFAULT, 1 });
    }
    return n;
}

int stability_ptr_methods(const Method *methods, int n)
{
    int count = 0;
    for (int i = 0; i < n; i++)
        count += methods[i].is_ptr;
    return count;
}

int stability_ptr_levels(void)
{
    return 1 + (ptr_isect_has_asm() ? (int)ptr_cpu_level() - PTR_CPU_NONE : 0);
}
