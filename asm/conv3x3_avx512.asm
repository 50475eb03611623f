; The denoiser's 3x3 convolution (denoise/conv.h), AVX-512 F. While two
; blocks of output channels are left, groups of 6 pixels x 32 channels: each
; input value broadcast once feeds two fused multiply-adds, as in the AVX2
; kernel, and each step's weights (two registers) feed 6 pixels: 12 FMAs to
; 8 loads, in 12 independent chains. Where one block is left (the last of
; 16, 48, 80 or 112 channels): groups of 8 pixels x 16 channels, 8 FMAs to 9
; loads in 8 chains, as many as two FMA units of latency 4 keep busy. With
; groups of 8 x 16 alone the convolutions went at 48-51% of the FMA peak on
; one thread, with these at 70% (bench/denoise, docs/convolutions.md);
; groups of 8 x 32, with zmm16-19 for the weights, went no faster. Each
; lane's chain is ptr_conv3x3_c's, so the output is the same bit for bit.
; The input stays the multiplication's first operand (not a broadcast from
; memory, which can only be the second), so that where several operands are
; NaN the CPU picks the same one at every level.

%include "ptr.inc"

CONV_PIXELS equ 8
%define CONV_PAIR_PIXELS 6

; One block: zmm(k) pixel k's 16 output channels; zmm8 the step's weights,
; zmm9 an input value, zmm10 zero. Two blocks: zmm(k), zmm(k + 6) pixel k's
; channels 0-15 and 16-31; zmm12, zmm13 the step's weights, zmm14 an input
; value, zmm15 zero. Only zmm0-15, whose upper halves vzeroupper clears.

; lo, hi = the numbers of pixel %1's registers of the first and second block.
%macro ACC_PAIR 1
%assign lo %1
%assign hi %1 + CONV_PAIR_PIXELS
%endmacro

%macro ACC_BIAS 1
    vmovups     zmm0, [rcx]
%if %1 == 2
    vmovups     zmm%[CONV_PAIR_PIXELS], [rcx + 64]
%endif
%endmacro

%macro ACC_COPY 2
    ACC_PAIR    %1
    vmovaps     zmm%[lo], zmm0
%if %2 == 2
    vmovaps     zmm%[hi], zmm%[CONV_PAIR_PIXELS]
%endif
%endmacro

%macro ACC_WEIGHTS 2
%if %2 == 1
    vmovups     zmm8, [r12 + 64 * %1]
%else
    vmovups     zmm12, [r12 + 64 * %1]
    vmovups     zmm13, [r12 + rbp + 64 * %1]
%endif
%endmacro

%macro ACC_FMA 3
    ACC_PAIR    %1
%if %3 == 1
    vbroadcastss zmm9, [INPUT(%1) + 4 * %2]
    vfmadd231ps zmm%[lo], zmm9, zmm8
%else
    vbroadcastss zmm14, [INPUT(%1) + 4 * %2]
    vfmadd231ps zmm%[lo], zmm14, zmm12
    vfmadd231ps zmm%[hi], zmm14, zmm13
%endif
%endmacro

%macro ACC_ZERO 1
%if %1 == 1
    vpxord      zmm10, zmm10, zmm10
%else
    vpxord      zmm15, zmm15, zmm15
%endif
%endmacro

%macro ACC_RELU 2
    ACC_PAIR    %1
%if %2 == 1
    vmaxps      zmm%[lo], zmm%[lo], zmm10
%else
    vmaxps      zmm%[lo], zmm%[lo], zmm15
    vmaxps      zmm%[hi], zmm%[hi], zmm15
%endif
%endmacro

%macro ACC_STORE 2
    ACC_PAIR    %1
    vmovups     [OUTPUT(%1)], zmm%[lo]
%if %2 == 2
    vmovups     [OUTPUT(%1) + 64], zmm%[hi]
%endif
%endmacro

%include "conv3x3.inc"

CONV3X3 ptr_conv3x3_avx512

section .note.GNU-stack noalloc noexec nowrite progbits
