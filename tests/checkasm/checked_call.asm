; Test support for the checker (not a kernel): calls a kernel (a closest-hit
; function, a convolution) with every System V callee-saved register holding
; a known value, then reports which survived, and whether the function left
; the upper halves of the YMM registers dirty (it must end AVX code with
; vzeroupper).

%include "ptr.inc"

CHECK_XINUSE     equ 0 ; CheckedCallStatus.check_xinuse: XGETBV(1) is usable
FAILURES         equ 4 ; CheckedCallStatus.failures

FAIL_CALLEE_SAVED equ 1
FAIL_VZEROUPPER   equ 2

%macro SENTINELS 0
    mov         rbx, 0x1b0fa4c6d39e2751
    mov         rbp, 0x2c1e95b7e48f3862
    mov         r12, 0x3d2f86a8f57e4973
    mov         r13, 0x4e4077990a6d5a84
    mov         r14, 0x5f5168aa1b5c6b95
    mov         r15, 0x606259bb2c4b7ca6
%endmacro

%macro EXPECT 2 ; register, value
    mov         r10, %2
    cmp         %1, r10
    setne       cl
    or          r11b, cl
%endmacro

; The call itself, from a frame of six saved registers and %1 bytes that
; holds the CheckedCallStatus pointer at [rsp + %2]: rax the function, its
; arguments in place. Returns the function's eax.
%macro CHECKED_CALL 2
    mov         r11, [rsp + %2]                 ; r11: no argument's register
    cmp         dword [r11 + CHECK_XINUSE], 0
    je          %%call
    vzeroupper                                  ; start clean
%%call:
    SENTINELS
    call        rax
    mov         r8d, eax
    xor         r11d, r11d
    EXPECT      rbx, 0x1b0fa4c6d39e2751
    EXPECT      rbp, 0x2c1e95b7e48f3862
    EXPECT      r12, 0x3d2f86a8f57e4973
    EXPECT      r13, 0x4e4077990a6d5a84
    EXPECT      r14, 0x5f5168aa1b5c6b95
    EXPECT      r15, 0x606259bb2c4b7ca6
    mov         r9, [rsp + %2]
    mov         r10d, r11d                      ; FAIL_CALLEE_SAVED if any differed
    cmp         dword [r9 + CHECK_XINUSE], 0
    je          %%report
    mov         ecx, 1
    xgetbv                                      ; XINUSE: bit 2 = upper YMM in use
    test        eax, 4
    jz          %%report
    or          r10d, FAIL_VZEROUPPER
%%report:
    or          [r9 + FAILURES], r10d
    mov         eax, r8d
    add         rsp, %1
    pop         r15
    pop         r14
    pop         r13
    pop         r12
    pop         rbx
    pop         rbp
    ret
%endmacro

%macro SAVE_REGISTERS 1 ; then %1 bytes of frame
    push        rbp
    push        rbx
    push        r12
    push        r13
    push        r14
    push        r15
    sub         rsp, %1
%endmacro

section .text

; int ptr_checked_call(PtrClosestHitFn fn, const PtrRay *ray,
;                      const PtrSpheres *spheres, size_t count, PtrHit *hit,
;                      CheckedCallStatus *status);
; int ptr_checked_call_bvh(PtrBvhClosestHitFn fn, const PtrRay *ray,
;                          const PtrBvh *bvh, const PtrSpheres *spheres,
;                          PtrHit *hit, CheckedCallStatus *status);
; void ptr_checked_call_packet(PtrClosestHitPacketFn fn,
;                              const PtrRayPacket *rays, const PtrSpheres *spheres,
;                              size_t count, PtrHitPacket *hits, CheckedCallStatus *status);
; void ptr_checked_call_bvh_packet(PtrBvhClosestHitPacketFn fn,
;                                  const PtrRayPacket *rays, const PtrBvh *bvh,
;                                  const PtrSpheres *spheres, PtrHitPacket *hits,
;                                  CheckedCallStatus *status);
; the same routine: it only forwards four arguments.
    global ptr_checked_call_bvh:function hidden
    global ptr_checked_call_packet:function hidden
    global ptr_checked_call_bvh_packet:function hidden
FUNCTION ptr_checked_call
ptr_checked_call_bvh:
ptr_checked_call_packet:
ptr_checked_call_bvh_packet:
    SAVE_REGISTERS 24                           ; 16-byte aligned at the call
    mov         [rsp], r9
    mov         rax, rdi
    mov         rdi, rsi
    mov         rsi, rdx
    mov         rdx, rcx
    mov         rcx, r8
    CHECKED_CALL 24, 0

; void ptr_checked_call_conv3x3(PtrConv3x3Fn fn, const ConvCall *call,
;                               CheckedCallStatus *status);
; ConvCall (checkasm.h) holds PTR_DECL_CONV3X3's nine arguments in order:
; six in registers, three on the stack.
CONV_STACK_ARGS  equ 48                         ; ConvCall.in_channels, then out_channels, relu
FUNCTION ptr_checked_call_conv3x3
    SAVE_REGISTERS 40                           ; 16-byte aligned at the call
    mov         [rsp + 24], rdx
    mov         rax, rdi
    mov         r10, rsi
    mov         r11, [r10 + CONV_STACK_ARGS]
    mov         [rsp], r11
    mov         r11, [r10 + CONV_STACK_ARGS + 8]
    mov         [rsp + 8], r11
    mov         r11d, [r10 + CONV_STACK_ARGS + 16]
    mov         [rsp + 16], r11
    mov         rdi, [r10]
    mov         rsi, [r10 + 8]
    mov         rdx, [r10 + 16]
    mov         rcx, [r10 + 24]
    mov         r8, [r10 + 32]
    mov         r9, [r10 + 40]
    CHECKED_CALL 40, 24

section .note.GNU-stack noalloc noexec nowrite progbits
