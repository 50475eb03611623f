; The denoiser's 3x3 convolution (denoise/conv.h), AVX2 with FMA: groups of
; 6 pixels x 16 output channels, two ymm registers a pixel. Each input
; channel's 16 weights are loaded once for the group and each input value
; broadcast once for its 16 channels: 12 fused multiply-adds to 8 loads, in
; 12 independent chains. Each lane's chain is ptr_conv3x3_c's, so the output
; is the same bit for bit.

%include "ptr.inc"

CONV_PIXELS equ 6

; ymm(2k), ymm(2k + 1): pixel k's output channels 0-7 and 8-15.
; ymm12, ymm13: the step's weights; ymm14: an input value; ymm15: zero.
; Groups are of one block (no CONV_PAIR_PIXELS: two blocks' accumulators
; would not fit in 16 registers), so each macro's block count is 1.

; lo, hi = the numbers of pixel %1's two registers.
%macro ACC_PAIR 1
%assign lo 2 * %1
%assign hi 2 * %1 + 1
%endmacro

%macro ACC_BIAS 1
%if %1 != 1
%error "the AVX2 kernel's groups are of one block"
%endif
    vmovups     ymm0, [rcx]
    vmovups     ymm1, [rcx + 32]
%endmacro

%macro ACC_COPY 2
    ACC_PAIR    %1
    vmovaps     ymm%[lo], ymm0
    vmovaps     ymm%[hi], ymm1
%endmacro

%macro ACC_WEIGHTS 2
    vmovups     ymm12, [r12 + 64 * %1]
    vmovups     ymm13, [r12 + 64 * %1 + 32]
%endmacro

%macro ACC_FMA 3
    ACC_PAIR    %1
    vbroadcastss ymm14, [INPUT(%1) + 4 * %2]
    vfmadd231ps ymm%[lo], ymm14, ymm12
    vfmadd231ps ymm%[hi], ymm14, ymm13
%endmacro

%macro ACC_ZERO 1
    vxorps      ymm15, ymm15, ymm15
%endmacro

%macro ACC_RELU 2
    ACC_PAIR    %1
    vmaxps      ymm%[lo], ymm%[lo], ymm15
    vmaxps      ymm%[hi], ymm%[hi], ymm15
%endmacro

%macro ACC_STORE 2
    ACC_PAIR    %1
    vmovups     [OUTPUT(%1)], ymm%[lo]
    vmovups     [OUTPUT(%1) + 32], ymm%[hi]
%endmacro

%include "conv3x3.inc"

CONV3X3 ptr_conv3x3_avx2

section .note.GNU-stack noalloc noexec nowrite progbits
