; Closest hit of one ray in the tree (src/accel/bvh.h), AVX2: a node's eight
; child boxes in one step, a leaf's spheres (up to sixteen) eight at a time.
; Returns exactly what ptr_bvh_closest_hit_c returns: the box test and the
; sphere arithmetic are the same operations in the same order (no FMA; maxps
; and minps where C writes its max and min), so the same boxes are visited
; or safely skipped and every t is the brute-force kernel's bit for bit. The
; answer, the smallest (t, id) with tmin < t < tmax, does not depend on the
; order of the visits; this kernel visits a node's nearest child first, as C
; does, and the others in lane order.

%include "ptr.inc"
%include "layout.inc"
%include "sphere_math.inc"
%include "bvh.inc"

section .rodata
align 32
lane_index: dd 0, 1, 2, 3, 4, 5, 6, 7
sign_mask:  times 8 dd 0x80000000
slack:      times 8 dd PTR_BVH_SLACK
infinity:   times 8 dd 0x7f800000
minus_infinity: dd 0xff800000

section .text

; The frame, at rbp aligned to 32: the ray's origin and clamped
; reciprocal direction broadcast to 8 lanes, the children's entry distances,
; best * PTR_BVH_SLACK broadcast, then the traversal stack of 16-byte
; entries (child, leaf count, entry distance, unused); also the count of the
; huge spheres left out of the tree, which are tested last (the tree's first node
; test need not wait on their square roots), and the rsp to return with.
ORG_X   equ 0
ORG_Y   equ 32
ORG_Z   equ 64
INV_X   equ 96
INV_Y   equ 128
INV_Z   equ 160
ENTRY   equ 192
BEST_UP equ 224
KEPT_OUT equ 256
STACK   equ 288
FRAME   equ STACK + 16 * (PTR_BVH_MAX_DEPTH * 7 + 1) + 32    ; the rsp in the last 8

; Tests spheres eax .. eax + ecx - 1 (1 <= ecx <= 8): for every lane
; whose t beats the best, (t, position) lexicographically; the smallest such
; t, at its lowest lane, becomes the best.
; In: r8-r11 cx, cy, cz, radius; r15d the best sphere; ymm0-2
; direction; ymm3 tmin; ymm4 best t in every lane; ymm6 lane indices; ymm7
; sign mask; rbp the frame. Out: ymm4, r15d and [rbp + BEST_UP] updated.
; Clobbers rdx, rcx, ymm8-15.
test_eight:
    OFFSETS_AVX2
    DISCRIMINANT y, vmovups
    vxorps      ymm14, ymm14, ymm14
    vcmpps      ymm14, ymm12, ymm14, CMP_GE_OQ  ; disc >= 0
    vmovd       xmm15, ecx
    vpbroadcastd ymm15, xmm15
    vpcmpgtd    ymm15, ymm15, ymm6              ; lane < count
    vandps      ymm14, ymm14, ymm15
    vtestps     ymm14, ymm14
    jz          .done                           ; no lane can hit: skip sqrt, div
    ROOT_AVX2
    vcmpps      ymm12, ymm9, ymm3, CMP_GT_OQ
    vandps      ymm14, ymm14, ymm12             ; tmin < t
    vcmpps      ymm12, ymm9, ymm4, CMP_EQ_OQ
    vandps      ymm12, ymm12, ymm14             ; t == best: the positions decide
    vcmpps      ymm15, ymm9, ymm4, CMP_LT_OQ
    vandps      ymm14, ymm14, ymm15             ; t < best
    vtestps     ymm12, ymm12
    jnz         .tie
.settled:
    vmovmskps   edx, ymm14
    test        edx, edx
    jz          .done
    vmovaps     ymm10, [infinity]
    vblendvps   ymm11, ymm10, ymm9, ymm14       ; the winners' t, else +inf
    vextractf128 xmm8, ymm11, 1
    vminps      xmm8, xmm8, xmm11
    HORIZONTAL_MIN_XMM8
    vinsertf128 ymm10, ymm8, xmm8, 1
    vcmpps      ymm10, ymm11, ymm10, CMP_EQ_OQ
    vandps      ymm10, ymm10, ymm14
    vmovmskps   edx, ymm10
    bsf         edx, edx                        ; the lowest winning lane
    add         edx, eax
    mov         r15d, edx
    vbroadcastss ymm4, xmm8                     ; best
    vmulps      ymm8, ymm4, [slack]
    vmovaps     [rbp + BEST_UP], ymm8
.done:
    ret
    ; A t equal to the best one's: the first in the arrays wins, decided for
    ; every lane by the first one's position (as in the AVX-512 kernel).
.tie:
    cmp         eax, r15d
    jge         .settled
    vorps       ymm14, ymm14, ymm12
    jmp         .settled

TEST_LEAF_BY_EIGHT

; int ptr_bvh_closest_hit_avx2(const PtrRay *ray, const PtrBvh *bvh,
;                              const PtrSpheres *spheres, PtrHit *hit);
;
; rdi ray, rsi bvh (then the node being tested), rdx spheres (then scratch),
; rcx hit (pushed; then scratch)
; r8-r11 cx, cy, cz, radius   r13 nodes   r14 stack top
; r15d best sphere (PTR_NO_HIT)   rbx where the nearest child was pushed
; rbp the frame
; ymm0-2 dx, dy, dz   ymm3 tmin   ymm4 best t   ymm6 lane indices
; ymm7 sign mask   ymm8-15 scratch
FUNCTION ptr_bvh_closest_hit_avx2
    TREE_ENTRY  FRAME, 32
    mov         [rbp + KEPT_OUT], rbx
    vbroadcastss ymm0, [rdi + RAY_DIR_X]
    vbroadcastss ymm1, [rdi + RAY_DIR_Y]
    vbroadcastss ymm2, [rdi + RAY_DIR_Z]
    vbroadcastss ymm3, [rdi + RAY_TMIN]
    vbroadcastss ymm4, [rdi + RAY_TMAX]
    vmovdqu     ymm6, [lane_index]
    vmovups     ymm7, [sign_mask]
    mov         r15d, -1                        ; PTR_NO_HIT
    vmulps      ymm8, ymm4, [slack]
    vmovaps     [rbp + BEST_UP], ymm8

.tree:
    test        r13, r13
    jz          .huge
    ; Per ray: origin, and 1 / dir clamped to +-FLT_MAX (finite or zero
    ; products, never NaN), each in 8 lanes.
    vbroadcastss ymm8, [rdi + RAY_ORG_X]
    vmovaps     [rbp + ORG_X], ymm8
    vbroadcastss ymm8, [rdi + RAY_ORG_Y]
    vmovaps     [rbp + ORG_Y], ymm8
    vbroadcastss ymm8, [rdi + RAY_ORG_Z]
    vmovaps     [rbp + ORG_Z], ymm8
    mov         eax, 0x3f800000                 ; 1.0f
    vmovd       xmm9, eax
    vbroadcastss ymm9, xmm9
    mov         eax, 0x7f7fffff                 ; FLT_MAX
    vmovd       xmm10, eax
    vbroadcastss ymm10, xmm10
    vxorps      ymm11, ymm10, ymm7              ; -FLT_MAX
%assign axis 0
%rep 3
    vdivps      ymm8, ymm9, %cond(axis == 0, ymm0, %cond(axis == 1, ymm1, ymm2))
    vmaxps      ymm8, ymm8, ymm11
    vminps      ymm8, ymm8, ymm10
    vmovaps     [rbp + INV_X + 32 * axis], ymm8
%assign axis axis + 1
%endrep
    lea         r14, [rbp + STACK]
    mov         qword [r14], 0                  ; the root: node 0, not a leaf
    mov         eax, [minus_infinity]
    mov         [r14 + 8], eax
    add         r14, 16

.pop:
    lea         rax, [rbp + STACK]
    cmp         r14, rax
    je          .huge
    sub         r14, 16
    vmovss      xmm8, [r14 + 8]
    vucomiss    xmm8, [rbp + BEST_UP]
    ja          .pop                            ; entered beyond the best hit
    mov         eax, [r14]
    mov         ecx, [r14 + 4]
    test        ecx, ecx
    jz          .node
    call        test_leaf
    jmp         .pop

.node:
    shl         rax, 8                          ; 256-byte nodes
    lea         rsi, [r13 + rax]
    ; tn and tf per axis: the near plane is lower where 1 / dir has its
    ; sign bit clear, else upper (vblendvps picks by that sign bit).
%assign axis 0
%rep 3
    vmovaps     ymm8, [rsi + NODE_LOWER_X + 64 * axis]
    vsubps      ymm8, ymm8, [rbp + ORG_X + 32 * axis]
    vmovaps     ymm15, [rbp + INV_X + 32 * axis]
    vmulps      ymm8, ymm8, ymm15               ; (lower - org) * inv
    vmovaps     ymm9, [rsi + NODE_UPPER_X + 64 * axis]
    vsubps      ymm9, ymm9, [rbp + ORG_X + 32 * axis]
    vmulps      ymm9, ymm9, ymm15               ; (upper - org) * inv
    vblendvps   %cond(axis == 0, ymm10, %cond(axis == 1, ymm11, ymm12)), ymm8, ymm9, ymm15
    vblendvps   %cond(axis == 0, ymm13, %cond(axis == 1, ymm14, ymm8)), ymm9, ymm8, ymm15
%assign axis axis + 1
%endrep
    vmaxps      ymm10, ymm10, ymm11
    vmaxps      ymm10, ymm10, ymm12
    vmaxps      ymm10, ymm10, ymm3              ; entry = max(tn x, y, z, tmin)
    vminps      ymm13, ymm13, ymm14
    vminps      ymm13, ymm13, ymm8
    vmulps      ymm13, ymm13, [slack]
    vminps      ymm13, ymm13, [rbp + BEST_UP]   ; exit = min(min(tf) * slack, best_up)
    vcmpps      ymm13, ymm10, ymm13, CMP_LE_OQ
    vmovmskps   edx, ymm13
    test        edx, edx
    jz          .pop
    ; One child entered: enter it. Several: push them all, swap the nearest
    ; (its lowest lane on a tie) onto the top, and pop it at once. The
    ; nearest so far is kept without a branch on the distances, which no
    ; predictor learns: a mispredicted branch throws away the steps after it.
    lea         ecx, [rdx - 1]
    test        edx, ecx
    jz          .one
    vmovaps     [rbp + ENTRY], ymm10
    vmovss      xmm15, [infinity]
    mov         rbx, r14
.push:
    bsf         ecx, edx
    btr         edx, ecx
    mov         eax, [rsi + NODE_CHILD + rcx*4]
    mov         [r14], eax
    mov         eax, [rsi + NODE_LEAF_COUNT + rcx*4]
    mov         [r14 + 4], eax
    vmovss      xmm8, [rbp + ENTRY + rcx*4]
    vmovss      [r14 + 8], xmm8
    vucomiss    xmm8, xmm15
    cmovb       rbx, r14                        ; nearer than the nearest so far
    vminss      xmm15, xmm8, xmm15              ; (never NaN: tmin is maxps's last operand)
    add         r14, 16
    test        edx, edx
    jnz         .push
    vmovups     xmm8, [rbx]
    vmovups     xmm9, [r14 - 16]
    vmovups     [rbx], xmm9
    vmovups     [r14 - 16], xmm8
    jmp         .pop
.one:
    bsf         ecx, edx
    mov         eax, [rsi + NODE_CHILD + rcx*4]
    mov         ecx, [rsi + NODE_LEAF_COUNT + rcx*4]
    test        ecx, ecx
    jz          .node
    call        test_leaf
    jmp         .pop

    ; The huge spheres left out of the tree, eight at a time, once the tree has
    ; found its best: the tree's first node test need not wait for them.
.huge:
    TEST_KEPT_OUT [rbp + KEPT_OUT]
.finish:
    TREE_LEAVE_FRAME FRAME
    TREE_RETURN_HIT

section .note.GNU-stack noalloc noexec nowrite progbits
