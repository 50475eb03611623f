; The machine's peak of fused multiply-adds, for bench/denoise: a loop of
; nothing but independent vfmadd231ps, in 12 chains (more than an FMA
; unit's latency times the units, on any x86-64 core). The operands are
; zeros: no denormal slows a step, and no value grows.

%include "ptr.inc"

FMA_CHAINS equ 12

; The loop on registers of kind %1 (ymm, zmm): rdi iterations.
%macro FMA_LOOP 1
    vpxor       xmm12, xmm12, xmm12
    vpxor       xmm13, xmm13, xmm13
%assign k 0
%rep FMA_CHAINS
    vmovaps     %1%[k], %1 %+ 12
%assign k k + 1
%endrep
%%iteration:
%assign k 0
%rep FMA_CHAINS
    vfmadd231ps %1%[k], %1 %+ 12, %1 %+ 13
%assign k k + 1
%endrep
    dec         rdi
    jnz         %%iteration
    vzeroupper
    ret
%endmacro

section .text

; void ptr_fma_peak_avx2(uint64_t iterations): 12 x 8 lanes x 2 flops an
; iteration.
FUNCTION ptr_fma_peak_avx2
    FMA_LOOP    ymm

; void ptr_fma_peak_avx512(uint64_t iterations): 12 x 16 lanes x 2 flops.
FUNCTION ptr_fma_peak_avx512
    FMA_LOOP    zmm

section .note.GNU-stack noalloc noexec nowrite progbits
