; The denoiser's 3x3 convolution (denoise/conv.h), AVX-512 F: groups of 8
; pixels x 16 output channels, one zmm register a pixel (eight independent
; chains, as many as two FMA units of latency 4 keep busy). Each input
; channel's 16 weights are loaded once for the group and each input value
; broadcast once for its 16 channels. Each lane's chain is
; ptr_conv3x3_c's, so the output is the same bit for bit. The walk is
; conv3x3.inc's, and the arithmetic the AVX2 kernel's with one register where
; that has two: the input stays the multiplication's first operand (not a
; broadcast from memory, which can only be the second), so that where
; several operands are NaN the CPU picks the same one at both levels.

%include "ptr.inc"

CONV_PIXELS equ 8

; zmm(k): pixel k's 16 output channels. zmm8: the step's weights; zmm9: an
; input value; zmm10: zero. Only zmm0-15, whose upper halves vzeroupper
; clears.

%macro ACC_BIAS 0
    vmovups     zmm0, [rcx]
%endmacro

%macro ACC_COPY 2
    vmovaps     zmm%[%1], zmm0
%endmacro

%macro ACC_WEIGHTS 1
    vmovups     zmm8, [r12 + 64 * %1]
%endmacro

%macro ACC_FMA 2
    vbroadcastss zmm9, [INPUT(%1) + 4 * %2]
    vfmadd231ps zmm%[%1], zmm9, zmm8
%endmacro

%macro ACC_ZERO 0
    vpxord      zmm10, zmm10, zmm10
%endmacro

%macro ACC_RELU 2
    vmaxps      zmm%[%1], zmm%[%1], zmm10
%endmacro

%macro ACC_STORE 2
    vmovups     [OUTPUT(%1)], zmm%[%1]
%endmacro

%include "conv3x3.inc"

CONV3X3 ptr_conv3x3_avx512

section .note.GNU-stack noalloc noexec nowrite progbits
